#!/usr/bin/env bash
# sinew-bench --dynamic on a tiny finger ("Dynamics measured, not assumed"):
# the run finishes and its JSON line carries every dynamic figure as a finite number
# (err_dyn_increment, dyn_increment_ratio and dyn_increment_cos may be null only without
# the reference's quasistatic clip, which this run has). No thresholds: the figures themselves are measured at full size; and
# --hold-frames without --dynamic is refused.
#   bash tests/bench_dynamic.sh BUILD_DIR
set -uo pipefail
bench=$1/tools/sinew-bench
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if ! "$bench" --scene finger --tets 1500 --frames 4 --dynamic --hold-frames 3 \
    --contract-steps 0 --threads 2 --json >"$tmp/out" 2>"$tmp/err"; then
    echo "FAIL: sinew-bench --dynamic exited non-zero:" >&2
    tail -n 5 "$tmp/err" >&2
    exit 1
fi
json=$(tail -n 1 "$tmp/out")
fails=0
for k in err_dynamic err_dynamic_hold overshoot_sub overshoot_full overshoot_ratio \
    settle_sub settle_full err_dyn_increment dyn_increment_rms dyn_increment_ratio \
    dyn_increment_cos dyn_dt dyn_rayleigh_alpha \
    dyn_rayleigh_beta dyn_full_ms dyn_sub_ms dyn_step_ms dyn_qs_step_ms dyn_vs_qs dyn_step_evals \
    dyn_qs_step_evals err_dynamic_ref err_dynamic_ref_hold err_dynamic_tight; do
    val=$(printf '%s' "$json" | grep -oE "\"$k\":[^,}]*" | head -n 1 | cut -d: -f2)
    if ! printf '%s' "$val" | grep -qE '^-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?$'; then
        echo "FAIL: $k is '${val:-missing}', not a finite number" >&2
        fails=$((fails + 1))
    fi
done
for k in hold_frames dyn_ref_failed dyn_sub_failed; do
    printf '%s' "$json" | grep -qE "\"$k\":[0-9]+" || {
        echo "FAIL: $k missing" >&2
        fails=$((fails + 1))
    }
done
printf '%s' "$json" | grep -q '"hold_frames":3' || { echo "FAIL: hold_frames is not 3" >&2; fails=$((fails + 1)); }
if "$bench" --scene finger --tets 1500 --frames 4 --hold-frames 3 >/dev/null 2>"$tmp/err" ||
    ! grep -q -- "--hold-frames applies only with --dynamic" "$tmp/err"; then
    echo "FAIL: --hold-frames without --dynamic was not refused" >&2
    fails=$((fails + 1))
fi
# the reference without self-contact says so in its JSON (what it changes is measured on
# the Fox: docs/notes/jiggle.md, What holds the Fox still)
printf '%s' "$json" | grep -q '"ref_self_contact":1' ||
    { echo "FAIL: ref_self_contact is not 1 by default" >&2; fails=$((fails + 1)); }
if ! "$bench" --scene finger --tets 1500 --frames 4 --dynamic --hold-frames 3 --contract-steps 0 \
    --threads 2 --ref-self-contact off --json 2>/dev/null | tail -n 1 |
    grep -q '"ref_self_contact":0'; then
    echo "FAIL: --ref-self-contact off not in the JSON" >&2
    fails=$((fails + 1))
fi
[ "$fails" -eq 0 ] && echo "bench_dynamic: ok"
exit "$fails"
