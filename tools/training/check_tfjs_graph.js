// Runs a TensorFlow.js model on a given input with TensorFlow.js itself (CPU backend, pure JavaScript) and
// writes the requested nodes' values, so that check_tfjs_graph.py can compare them with tfjs_graph.py's
// interpreter (graph models) or keras_layers.py's (layers models: NODE names a layer, INPUT is NHWC).
//
//   npm install @tensorflow/tfjs-core@4 @tensorflow/tfjs-converter@4 @tensorflow/tfjs-layers@4 \
//               @tensorflow/tfjs-backend-cpu@4
//   node check_tfjs_graph.js MODEL_DIR MODEL.json INPUT.bin SHAPE OUT_PREFIX NODE...
//
// INPUT.bin holds float32 values in the input's shape (SHAPE, comma-separated); OUT_PREFIX<i>.bin receives
// node i's values (float32) and OUT_PREFIX<i>.shape its shape.
const fs = require('fs');
const path = require('path');
const tf = require('@tensorflow/tfjs-core');
require('@tensorflow/tfjs-backend-cpu');

// The layers of `net` up to `names`, rebuilt on an input of shape `dims` (the stored model fixes its input
// size); the copy shares the loaded weights.
function truncatedLayersModel(layers, net, names, dims) {
  const x = layers.input({shape: dims.slice(1)});
  const built = {[net.inputLayers[0].name]: x};
  const needed = new Set();
  const visit = (layer) => {
    if (needed.has(layer.name)) return;
    needed.add(layer.name);
    for (const node of layer.inboundNodes) for (const l of node.inboundLayers) visit(l);
  };
  names.forEach((n) => visit(net.getLayer(n)));
  for (const layer of net.layers) {
    if (!needed.has(layer.name) || built[layer.name]) continue;
    const sources = layer.inboundNodes[0].inboundLayers.map((l) => built[l.name]);
    built[layer.name] = layer.apply(sources.length === 1 ? sources[0] : sources);
  }
  return layers.model({inputs: x, outputs: names.map((n) => built[n])});
}

async function main() {
  const [dir, file, input, shape, prefix, ...nodes] = process.argv.slice(2);
  if (!nodes.length) {
    console.error('usage: node check_tfjs_graph.js MODEL_DIR MODEL.json INPUT.bin SHAPE OUT_PREFIX NODE...');
    process.exit(2);
  }
  const model = JSON.parse(fs.readFileSync(path.join(dir, file)));
  const shards = model.weightsManifest.flatMap((g) => g.paths.map((p) => fs.readFileSync(path.join(dir, p))));
  const weights = Buffer.concat(shards);
  const handler = {
    load: async () => ({
      modelTopology: model.modelTopology,
      weightSpecs: model.weightsManifest.flatMap((g) => g.weights),
      weightData: weights.buffer.slice(weights.byteOffset, weights.byteOffset + weights.byteLength),
      format: model.format,
      signature: model.signature,
    }),
  };
  await tf.setBackend('cpu');
  const raw = fs.readFileSync(input);
  const dims = shape.split(',').map(Number);
  const x = tf.tensor(new Float32Array(raw.buffer, raw.byteOffset, raw.length / 4), dims);
  let outputs;
  if (model.format === 'layers-model') {
    const layers = require('@tensorflow/tfjs-layers');
    const net = await layers.loadLayersModel(handler, {strict: false});
    outputs = truncatedLayersModel(layers, net, nodes, dims).predict(x);
  } else {
    const converter = require('@tensorflow/tfjs-converter');
    const net = await converter.loadGraphModel(handler);
    const inputName = Object.keys(model.signature.inputs)[0].split(':')[0];
    outputs = net.execute({[inputName]: x}, nodes);
  }
  (Array.isArray(outputs) ? outputs : [outputs]).forEach((t, i) => {
    fs.writeFileSync(`${prefix}${i}.bin`, Buffer.from(t.dataSync().buffer));
    fs.writeFileSync(`${prefix}${i}.shape`, t.shape.join(','));
  });
}

main().catch((e) => {
  console.error(e.message);
  process.exit(1);
});
