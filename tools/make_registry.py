"""Generate tiltlab's committed data registry from the data manifest.

Usage: python tools/make_registry.py [path/to/MANIFEST.json]
(default: $TILTLAB_DATA_DIR/MANIFEST.json, else ../shared/data/MANIFEST.json)

Writes src/tiltlab/_registry/registry.txt (pooch format: ``name sha256:HASH URL``) and
src/tiltlab/_registry/datasets.json (citations, licences and sizes).
"""

import json
import os
import sys
from pathlib import Path

root = Path(__file__).resolve().parents[1]
default = (
    Path(os.environ.get("TILTLAB_DATA_DIR", root.parent / "shared" / "data"))
    / "MANIFEST.json"
)
manifest = Path(sys.argv[1]) if len(sys.argv) > 1 else default
m = json.loads(manifest.read_text())
lines, meta = [], {"generated_from": "MANIFEST.json", "datasets": {}, "files": {}}
for name, d in sorted(m["datasets"].items()):
    meta["datasets"][name] = {"citation": d.get("citation", "")}
    for f in sorted(d["files"], key=lambda f: f["file"]):
        lines.append(f"{f['file']} sha256:{f['sha256']} {f['url']}")
        meta["files"][f["file"]] = {
            "dataset": name,
            "bytes": f["bytes"],
            "license": f.get("license", ""),
        }
out = root / "src" / "tiltlab" / "_registry"
out.mkdir(parents=True, exist_ok=True)
(out / "registry.txt").write_text("\n".join(lines) + "\n")
(out / "datasets.json").write_text(json.dumps(meta, indent=1, sort_keys=True) + "\n")
print(f"{len(lines)} files registered from {manifest}")
