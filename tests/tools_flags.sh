#!/usr/bin/env bash
# Every tool's flags as data (tools/common/tool_flags.h): each tool's --help, printed from
# its flag tables, exits 0; an unknown flag exits 2 with a message naming it; and
# docs/tools.md lists exactly the flags each tool takes: its section's "Flags" line is the
# one this script makes from --help. With --write it rewrites those lines (after a flag
# table changed).
#
# usage: bash tests/tools_flags.sh BUILD_DIR SOURCE_DIR [--write]
set -uo pipefail
build=$1
src=$2
write=${3:-}
doc=$src/docs/tools.md
tools="sinew-bake sinew-bench sinew-fullsim sinew-render sinew-invariance sinew-inspect sinew-soak sinew-replay"
# sinew-view is built only where GLFW, OpenGL and assimp are (samples/viewer/CMakeLists.txt)
[ -x "$build/tools/sinew-view" ] && tools="$tools sinew-view"
fails=0
fail() {
    echo "FAIL $*" >&2
    fails=$((fails + 1))
}

# The Flags line of a tool: its --help's flags (the first word of each flag line), in order.
flags_line() {
    local list
    # shellcheck disable=SC2016 # the backquotes are markdown's, not the shell's
    list=$(grep -oE '^  --[a-z0-9-]+' <<<"$1" | sed 's/^  //' | awk '!seen[$0]++' |
        sed 's/.*/`&`/' | paste -sd, - | sed 's/,/, /g')
    echo "Flags (\`$2 --help\` says what each takes): $list"
}

for tool in $tools; do
    exe=$build/tools/$tool
    help=$("$exe" --help) || fail "$tool --help exits $?"
    err=$("$exe" --no-such-flag 2>&1 >/dev/null)
    rc=$?
    [ "$rc" -eq 2 ] || fail "$tool --no-such-flag exits $rc, not 2"
    grep -q -- "unknown or incomplete argument '--no-such-flag'" <<<"$err" ||
        fail "$tool --no-such-flag: no message naming the flag: $err"
    want=$(flags_line "$help" "$tool")
    grep -qF -- "## $tool" "$doc" || fail "docs/tools.md has no section ## $tool"
    have=$(awk -v t="## $tool" '$0 == t { on = 1; next } on && /^## / { exit }
        on && /^Flags \(/ { print; exit }' "$doc")
    if [ "$write" = --write ]; then
        WANT=$want TOOL=$tool python3 - "$doc" <<'PY'
import os, sys
path, tool, want = sys.argv[1], os.environ["TOOL"], os.environ["WANT"]
lines = open(path).read().split("\n")
start = lines.index("## " + tool)
end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
at = next((i for i in range(start, end) if lines[i].startswith("Flags (")), None)
if at is not None:
    lines[at] = want
else:  # after the synopsis: the first indented block of the section
    i = start + 1
    while i < end and not lines[i].startswith("    "):
        i += 1
    while i < end and lines[i].startswith("    "):
        i += 1
    lines[i:i] = ["", want]
open(path, "w").write("\n".join(lines))
PY
    elif [ "$have" != "$want" ]; then
        fail "docs/tools.md's $tool Flags line is not its --help's (bash tests/tools_flags.sh" \
            "BUILD SOURCE --write rewrites it):
  docs:   $have
  --help: $want"
    fi
done
[ "$fails" -eq 0 ] && echo "tools_flags: every tool's --help, bad flag and docs/tools.md agree"
exit $((fails > 0))
