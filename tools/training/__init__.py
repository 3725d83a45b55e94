"""libg2p's material segmentation network: the recipe that trains it and exports it for the `onnx` backend
(docs/training.md).

Each step is a module with a main(), run from anywhere as a script or, from the repository root, as a module:

    python3 tools/training/train.py DATASET OUT ...     python3 -m tools.training.train DATASET OUT ...

The steps: attribution (the models a dataset used), train, soup (weights of sibling runs averaged), ensemble (runs
joined into one ONNX model), quantize (int8 weights), export_detector (NanoDet-g's whole detector as its own ONNX
file) with its reference decoder detect_objects, and the checks colour_baseline and check_tfjs_graph. The
training set itself is rendered by g2p_make_dataset (make_dataset.cpp, built with the C++ tools). train_kinds
trains the kind classifier on g2p_make_kind_dataset's renders (docs/kind-classifier.md).

Imports go one way: a module imports only modules listed before it in LAYERS (tests/tools/training_imports_test.py
checks it), so there is no cycle. Writing an export and reading one back sit below train, since train does both (it
starts from an export with --init and distils from runs with --teacher); soup and ensemble, which join trained runs
into the network that ships, sit on top. A new module takes its place in LAYERS.
"""

LAYERS = (
    # data: g2p_make_dataset's folders as training and validation rows, images, labels, augmentations
    "data",
    "attribution",
    # model: the networks, and the interpreters of the pretrained encoders from npm
    "tfjs_graph",
    "keras_layers",
    "model",
    "check_tfjs_graph",
    # validation scores
    "metrics",
    "colour_baseline",
    "val_labels",
    # export: what a run writes, int8 weights, weights recovered from an export, run folders read back as networks
    "export",
    "quantize",
    # NanoDet-g's whole COCO detector as its own ONNX file and card, and the reference decoder of that card
    "export_detector",
    "detect_objects",
    "onnx_weights",
    "runs",
    # train
    "train",
    # trained runs joined into the network that ships
    "soup",
    "ensemble",
    # the kind classifier (docs/kind-classifier.md): a head on the npm MobileNetV2, its ONNX file and card
    "train_kinds",
)
