// Validate glTF/GLB files with the Khronos glTF validator (npm package `gltf-validator`).
//
//   node tools/validate_gltf.cjs FILE.glb [VALIDATOR_DIR]
//
// VALIDATOR_DIR is the installed package folder (default: $ECS_TENTACLES_GLTF_VALIDATOR,
// else a normal `require`). Prints the validator's JSON report on stdout; exits 0 when it
// reports no errors, 1 when it does, 2 when the file cannot be validated at all.
"use strict";
const fs = require("fs");
const path = require("path");

const file = process.argv[2];
const where = process.argv[3] || process.env.ECS_TENTACLES_GLTF_VALIDATOR || "gltf-validator";
if (!file) {
  console.error("usage: node tools/validate_gltf.cjs FILE.glb [VALIDATOR_DIR]");
  process.exit(2);
}
const validator = require(where.startsWith(".") || path.isAbsolute(where) ? path.resolve(where) : where);
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), { uri: path.basename(file), maxIssues: 100 })
  .then((report) => {
    console.log(JSON.stringify(report, null, 2));
    process.exit(report.issues.numErrors === 0 ? 0 : 1);
  })
  .catch((error) => {
    console.error(String(error));
    process.exit(2);
  });
