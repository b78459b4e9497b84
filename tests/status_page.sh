#!/usr/bin/env bash
# docs/status.md is what tools/scripts/status_table.py makes of the JSON in docs/status/:
# a hand edit of the page, or JSON committed without the page regenerated, fails here.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
want=$(python3 "$root/tools/scripts/status_table.py" "$root/docs/status")
if [ "$want" != "$(cat "$root/docs/status.md")" ]; then
    echo "docs/status.md is not what tools/scripts/status_table.py makes of docs/status/:" >&2
    diff <(echo "$want") "$root/docs/status.md" >&2 || true
    echo "regenerate it: python3 tools/scripts/status_table.py docs/status > docs/status.md" >&2
    exit 1
fi
echo "docs/status.md matches docs/status/"
