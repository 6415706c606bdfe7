// Validates Kubernetes manifests against the API's schemas (the
// kubernetes-models package, generated from Kubernetes' OpenAPI schemas,
// and @kubernetes-models/prometheus-operator for the Operator's
// ServiceMonitor): every document of every file given must be a kind this
// knows, and valid. Prints one line per document; exits 1 when any is
// not.
//
//   node scripts/node/validate-manifests.mjs deploy/kubernetes/*.yaml

import { readFileSync } from "node:fs";
import yaml from "js-yaml";

// apiVersion -> the module holding its kinds.
const modules = {
  v1: "kubernetes-models/v1",
  "apps/v1": "kubernetes-models/apps/v1",
  "autoscaling/v2": "kubernetes-models/autoscaling/v2",
  "policy/v1": "kubernetes-models/policy/v1",
  "networking.k8s.io/v1": "kubernetes-models/networking.k8s.io/v1",
  "monitoring.coreos.com/v1":
    "@kubernetes-models/prometheus-operator/monitoring.coreos.com/v1",
};
// Not Kubernetes objects, but kustomize's own file: checked by kustomize.
const skipped = new Set(["kustomize.config.k8s.io/v1beta1/Kustomization"]);

let failed = 0;
for (const file of process.argv.slice(2)) {
  let documents;
  try {
    documents = yaml.loadAll(readFileSync(file, "utf8"));
  } catch (e) {
    console.log(`${file}: not YAML: ${e.message}`);
    failed++;
    continue;
  }
  for (const doc of documents) {
    if (doc == null) continue;
    const name = `${file}: ${doc.kind} ${doc.metadata?.name ?? ""}`.trim();
    if (skipped.has(`${doc.apiVersion}/${doc.kind}`)) {
      console.log(`${name}: skipped (kustomize's own)`);
      continue;
    }
    const module = modules[doc.apiVersion];
    let model;
    try {
      model = module && (await import(module))[doc.kind];
    } catch (e) {
      model = undefined;
    }
    if (!model) {
      console.log(`${name}: no schema for ${doc.apiVersion} ${doc.kind}`);
      failed++;
      continue;
    }
    try {
      new model(doc).validate();
      console.log(`${name}: valid ${doc.apiVersion} ${doc.kind}`);
    } catch (e) {
      console.log(`${name}: INVALID: ${e.message}`);
      failed++;
    }
  }
}
process.exit(failed > 0 ? 1 : 0);
