// Evaluates FHIRPath expressions with fhirpath.js (npm fhirpath, the engine LHC-Forms is built on,
// here in its own newer release), R4 model, on a QuestionnaireResponse with its Questionnaire as
// %questionnaire (where weight() finds each chosen option's score) and the response as %resource.
//
// Usage: node evaluate.mjs < {"expressions": [...], "resource": {...}, "questionnaire": {...}}
// Prints one JSON array: each expression's result (an array). Exit 1 with one line on stderr when
// an expression cannot be evaluated.
import { readFileSync } from 'node:fs';
import fhirpath from 'fhirpath';
import r4 from 'fhirpath/fhir-context/r4/index.js';

const input = JSON.parse(readFileSync(0, 'utf8'));
const env = { resource: input.resource, questionnaire: input.questionnaire };
try {
  const results = input.expressions.map((e) => fhirpath.evaluate(input.resource, e, env, r4));
  process.stdout.write(JSON.stringify(results) + '\n');
} catch (error) {
  process.stderr.write(`fhirpath.js: ${error.message}\n`);
  process.exit(1);
}
