// Validates scene or sweep files against their JSON Schema (`sim schema`) with Ajv, the
// validator of the JSON Schema ecosystem (its draft 2020-12 class, strict mode on), as an
// editor would:
//
//   node check_scenes.mjs SCHEMA.json FILE.json [FILE.json ...]
//
// Prints one JSON summary on stdout: {"schema", "files": [{"file", "valid", "errors"}],
// "invalid"}; each error is "<instance path> <message> <params>" (for a misspelt key,
// `additionalProperty` names it). Exit 0 if every file is valid, 1 if one is not (each on
// stderr), 2 on bad input (unreadable files, a schema Ajv refuses in strict mode).

import { readFileSync } from "node:fs";

import Ajv2020 from "ajv/dist/2020.js";

function main() {
  const [schemaPath, ...files] = process.argv.slice(2);
  if (!schemaPath || files.length === 0) {
    console.error("usage: node check_scenes.mjs SCHEMA.json FILE.json [FILE.json ...]");
    process.exit(2);
  }
  const schema = JSON.parse(readFileSync(schemaPath, "utf8"));
  // strict: unknown keywords or formats, ambiguous types and the like in the schema are errors;
  // union types (["number", "null"]) are what an `Option` is
  const ajv = new Ajv2020({ allErrors: true, strict: true, allowUnionTypes: true });
  const validate = ajv.compile(schema);
  const results = [];
  for (const file of files) {
    const data = JSON.parse(readFileSync(file, "utf8"));
    const valid = validate(data);
    const errors = valid ? [] : validate.errors.map((e) => `${e.instancePath || "/"} ${e.message} ${JSON.stringify(e.params)}`);
    results.push({ file, valid, errors });
    for (const e of errors) console.error(`${file}: ${e}`);
  }
  const invalid = results.filter((r) => !r.valid).length;
  console.log(JSON.stringify({ schema: schemaPath, files: results, invalid }, null, 1));
  process.exit(invalid ? 1 : 0);
}

try {
  main();
} catch (e) {
  console.error(`error: ${e.stack ?? e}`);
  process.exit(2);
}
