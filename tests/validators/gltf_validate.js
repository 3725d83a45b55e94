#!/usr/bin/env node
// Runs the Khronos glTF validator (npm gltf-validator) on .glb/.gltf files
// and prints one summary line per file; exits 1 when any file has an error
// (warnings and infos are printed, not failed), 2 on bad usage.
//
//   node tests/validators/gltf_validate.js FILE...
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0,
    // Buffers and images beside a .gltf are read from its folder.
    externalResourceFunction: (uri) =>
      new Promise((resolve, reject) => {
        fs.readFile(path.join(path.dirname(file), decodeURIComponent(uri)), (err, data) =>
          err ? reject(err.toString()) : resolve(new Uint8Array(data)));
      }),
  });
  const i = report.issues;
  console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos` +
              ` (gltf-validator ${report.validatorVersion})`);
  for (const m of i.messages)
    if (m.severity <= 1) console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code} at ${m.pointer || '-'}: ${m.message}`);
  return i.numErrors;
}

(async () => {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node gltf_validate.js FILE.glb...');
    process.exit(2);
  }
  let errors = 0;
  for (const f of files) {
    try {
      errors += await validate(f);
    } catch (e) {
      console.error(`${f}: cannot validate: ${e}`);
      errors += 1;
    }
  }
  process.exit(errors > 0 ? 1 : 0);
})();
