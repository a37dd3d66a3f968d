"""Print a YAML file (a Kubernetes manifest, a GitHub Actions workflow) as JSON, for
tests/cluster_examples.rs. PyYAML's own parser, so the test reads what kubectl and GitHub read."""
import json
import sys

import yaml

with open(sys.argv[1]) as f:
    docs = list(yaml.safe_load_all(f))
# YAML 1.1 reads the key `on` as true; JSON keys must be strings.
def keys(v):
    if isinstance(v, dict):
        return {str(k): keys(x) for k, x in v.items()}
    if isinstance(v, list):
        return [keys(x) for x in v]
    return v
json.dump(keys(docs[0] if len(docs) == 1 else docs), sys.stdout)
