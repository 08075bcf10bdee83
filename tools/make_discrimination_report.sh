#!/usr/bin/env bash
# Re-measures docs/golden-discrimination.md: the discrimination suite (refray golden discriminate) against
# tests/golden (320x180, what the CTest checks) and against envelope goldens made at 640x360 in a scratch
# directory, and writes each table between its markers in the doc. About 30 minutes on 2 cores.
#   bash tools/make_discrimination_report.sh [BUILD_DIR]      (default build/ci; needs refray and refray-fma)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/ci}
refray=$build/tools/refray
[ -x "$refray" ] || { echo "no $refray: build the ci preset first" >&2; exit 2; }
work=$(mktemp -d /tmp/refray-discrimination.XXXXXX)
trap 'rm -rf "$work"' EXIT

echo "== 320x180 against tests/golden"
"$refray" golden discriminate tests/golden --markdown "$work/320.md" || true
echo "== 640x360: making the envelope goldens"
"$refray" golden update --size 640x360 --dir "$work/goldens-640" | grep -v '^    '
echo "== 640x360 against them"
"$refray" golden discriminate "$work/goldens-640" --markdown "$work/640.md" || true

python3 - "$work/320.md" "$work/640.md" <<'PY'
import sys, re
doc_path = "docs/golden-discrimination.md"
doc = open(doc_path).read()
for size, path in (("320", sys.argv[1]), ("640", sys.argv[2])):
    table = open(path).read().strip()
    begin, end = "<!-- BEGIN %s -->" % size, "<!-- END %s -->" % size
    pattern = re.compile(re.escape(begin) + ".*?" + re.escape(end), re.S)
    if not pattern.search(doc):
        sys.exit("docs/golden-discrimination.md has no %s ... %s markers" % (begin, end))
    doc = pattern.sub(lambda m: begin + "\n" + table + "\n" + end, doc)
open(doc_path, "w").write(doc)
print("wrote", doc_path)
PY
