// Runs a TensorFlow.js graph model on a given input with TensorFlow.js itself (CPU backend, pure
// JavaScript) and writes the requested nodes' values, so that check_tfjs_graph.py can compare them
// with tfjs_graph.py's interpreter.
//
//   npm install @tensorflow/tfjs-core@4 @tensorflow/tfjs-converter@4 @tensorflow/tfjs-backend-cpu@4
//   node check_tfjs_graph.js MODEL_DIR GRAPH.json INPUT.bin N,C,H,W OUT_PREFIX NODE...
//
// INPUT.bin holds float32 values in the input's shape; OUT_PREFIX<i>.bin receives node i's values
// (float32) and OUT_PREFIX<i>.shape its shape.
const fs = require('fs');
const path = require('path');
const tf = require('@tensorflow/tfjs-core');
require('@tensorflow/tfjs-backend-cpu');
const converter = require('@tensorflow/tfjs-converter');

async function main() {
  const [dir, graph, input, shape, prefix, ...nodes] = process.argv.slice(2);
  if (!nodes.length) {
    console.error('usage: node check_tfjs_graph.js MODEL_DIR GRAPH.json INPUT.bin N,C,H,W OUT_PREFIX NODE...');
    process.exit(2);
  }
  const model = JSON.parse(fs.readFileSync(path.join(dir, graph)));
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
  const net = await converter.loadGraphModel(handler);
  const raw = fs.readFileSync(input);
  const x = tf.tensor(new Float32Array(raw.buffer, raw.byteOffset, raw.length / 4), shape.split(',').map(Number));
  const inputName = Object.keys(model.signature.inputs)[0].split(':')[0];
  const outputs = net.execute({[inputName]: x}, nodes);
  (Array.isArray(outputs) ? outputs : [outputs]).forEach((t, i) => {
    fs.writeFileSync(`${prefix}${i}.bin`, Buffer.from(t.dataSync().buffer));
    fs.writeFileSync(`${prefix}${i}.shape`, t.shape.join(','));
  });
}

main().catch((e) => {
  console.error(e.message);
  process.exit(1);
});
