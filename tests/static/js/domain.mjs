// The server's model kinds for the node tests: the GET /api/v1/domain
// answer that tests/static/test_editor_js.py writes to the file
// COATED_DOMAIN_JSON names, given to static/kinds.js on import.

import { readFileSync } from "node:fs";

import { setModelKinds } from "../../../static/kinds.js";

const file = process.env.COATED_DOMAIN_JSON;
if (!file) throw new Error("COATED_DOMAIN_JSON must name the domain's JSON (tests/static/test_editor_js.py writes it)");
export const DOMAIN = JSON.parse(readFileSync(file, "utf8"));
setModelKinds(DOMAIN);
