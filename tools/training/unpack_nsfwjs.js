// Unpacks the MobileNetV2 of the npm package nsfwjs (MIT; an ImageNet MobileNetV2 whose blocks up to
// block_10 were kept frozen while its head was trained on other classes) into a plain TensorFlow.js layers
// model: OUT/mobilenet_v2.json (Keras topology and weights manifest) and OUT/mobilenet_v2.bin. The package
// ships both as browserified modules (model.min.js, group1-shard1of1.min.js with the weights in base64);
// keras_layers.py reads the unpacked files. docs/training.md, "Pretrained encoders".
//
// usage: node unpack_nsfwjs.js PACKAGE_DIR OUT_DIR
//   (PACKAGE_DIR: the unpacked tarball of `npm pack nsfwjs@4.4.0`, i.e. its package/ folder)
"use strict";
const fs = require("fs");
const path = require("path");

function main(argv) {
  if (argv.length !== 2) {
    process.stderr.write("usage: node unpack_nsfwjs.js PACKAGE_DIR OUT_DIR\n");
    return 2;
  }
  const [pkg, out] = argv;
  const dir = path.join(pkg, "dist", "models", "mobilenet_v2");
  const modelJs = path.join(dir, "model.min.js");
  if (!fs.existsSync(modelJs)) {
    process.stderr.write(`${modelJs}: not found (is ${pkg} the package/ folder of nsfwjs 4.x?)\n`);
    return 1;
  }
  const model = require(path.resolve(modelJs));
  if (!model.modelTopology || !Array.isArray(model.weightsManifest)) {
    process.stderr.write(`${modelJs}: no modelTopology and weightsManifest\n`);
    return 1;
  }
  const blobs = [];
  for (const group of model.weightsManifest) {
    for (const p of group.paths) {
      const shard = require(path.resolve(dir, p + ".min.js"));
      if (typeof shard !== "string") {
        process.stderr.write(`${p}.min.js: expected a base64 string\n`);
        return 1;
      }
      blobs.push(Buffer.from(shard, "base64"));
    }
  }
  fs.mkdirSync(out, { recursive: true });
  const weights = model.weightsManifest.flatMap((g) => g.weights);
  const manifest = [{ paths: ["mobilenet_v2.bin"], weights }];
  fs.writeFileSync(path.join(out, "mobilenet_v2.bin"), Buffer.concat(blobs));
  fs.writeFileSync(path.join(out, "mobilenet_v2.json"),
                   JSON.stringify({ format: "layers-model", modelTopology: model.modelTopology,
                                    weightsManifest: manifest }));
  return 0;
}

process.exitCode = main(process.argv.slice(2));
