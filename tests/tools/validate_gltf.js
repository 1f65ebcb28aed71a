// Validates a glTF binary with the Khronos glTF-Validator (npm's gltf-validator, installed in
// viewer/node_modules by viewer/build); prints its issues as JSON.
const path = require("path");
const fs = require("fs");
const validator = require(path.join(__dirname, "..", "..", "viewer", "node_modules", "gltf-validator"));

const file = process.argv[2];
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)))
  .then((report) => console.log(JSON.stringify(report.issues)))
  .catch((error) => {
    console.error(`cannot validate ${file}: ${error}`);
    process.exit(1);
  });
