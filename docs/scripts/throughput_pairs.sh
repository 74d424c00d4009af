#!/usr/bin/env bash
# Throughput of two ttalloc binaries measured in the same run: interleaved pairs (old, new,
# old, new, ...) of the Monte Carlo (`mc`) and of `end-to-end` on the paper's study, with the
# same arguments and thread count. Prints one line per run and, per command, the ratio
# new/old of each pair (user CPU, wall, the command's own throughput) with its median, min
# and max; checks that both binaries give the same answer (the JSON apart from timings).
#
# Usage: throughput_pairs.sh OLD_BIN NEW_BIN [PAIRS] [OUTDIR]
#   run from the repository root (the study path is relative); PAIRS defaults to 5; PAIRS 0
#   prints the summary of the runs already in OUTDIR.
# Environment: THREADS (default 2; RAYON_NUM_THREADS and mc's --threads), MC_SAMPLES (default
# 1e9, about 18 s of CPU), E2E_SAMPLES (default 1e6, about 22 s of CPU), STUDY (default the
# paper's).
# Example: docs/scripts/throughput_pairs.sh /tmp/ttalloc-a8ee47e target/release/ttalloc 5 /tmp/pairs
set -u
old=$1; new=$2; pairs=${3:-5}; out=${4:-$(mktemp -d)}
threads=${THREADS:-2}
mc_samples=${MC_SAMPLES:-1e9}
e2e_samples=${E2E_SAMPLES:-1e6}
study=${STUDY:-studies/gyrowheel-2017.toml}
mkdir -p "$out"
export RAYON_NUM_THREADS=$threads
log=$out/runs.tsv
# PAIRS 0 only summarises the runs already in OUTDIR (e.g. of a run cut short)
[ "$pairs" -gt 0 ] && printf 'command\tpair\tbinary\tuser_s\twall_s\tthroughput\tload1\n' > "$log"
run() { # run CMD PAIR WHICH BIN
  local cmd=$1 pair=$2 which=$3 bin=$4 args
  case $cmd in
    mc) args=(mc --study "$study" --samples "$mc_samples" --threads "$threads" --json) ;;
    end-to-end) args=(end-to-end --study "$study" --samples "$e2e_samples" --json) ;;
  esac
  local base=$out/$cmd.$pair.$which load
  load=$(cut -d' ' -f1 /proc/loadavg)
  /usr/bin/time -f '%U %e' -o "$base.time" "$bin" "${args[@]}" > "$base.json" 2> "$base.err" || {
    echo "$which $cmd failed: $base.err" >&2; exit 1; }
  python3 - "$cmd" "$pair" "$which" "$base" "$load" >> "$log" <<'EOF'
import json, sys
cmd, pair, which, base, load = sys.argv[1:]
user, wall = open(base + ".time").read().split()[-2:]
d = json.load(open(base + ".json"))
# the command's own figure: mc's samples/s; end-to-end's fast path turntables/s (its
# `throughput` block, measured by the run on its own draws)
t = d["samples_per_sec"] if cmd == "mc" else d["throughput"]["fast_path_turntables_per_s"]
print(f"{cmd}\t{pair}\t{which}\t{user}\t{wall}\t{t:.6g}\t{load}")
EOF
  tail -n 1 "$log" >&2
}
for pair in $(seq 1 "$pairs"); do
  for cmd in mc end-to-end; do
    run "$cmd" "$pair" old "$old"
    run "$cmd" "$pair" new "$new"
  done
done
python3 - "$out" <<'EOF'
import json, statistics, sys
out = sys.argv[1]
rows = [l.rstrip("\n").split("\t") for l in open(f"{out}/runs.tsv")][1:]
TIMINGS = {"seconds", "samples_per_sec", "throughput"}
def answer(path):
    return {k: v for k, v in json.load(open(path)).items() if k not in TIMINGS}
def compare(a, b, path, added, changed):
    """Every value of the old answer `a` is the same in the new `b`; keys only in `b` are
    listed in `added` (features that landed after the old commit), the rest in `changed`."""
    if isinstance(a, dict) and isinstance(b, dict):
        for k in b.keys() - a.keys():
            added.add(f"{path}/{k}")
        for k in a.keys():
            if k in b:
                compare(a[k], b[k], f"{path}/{k}", added, changed)
            else:
                changed.add(f"{path}/{k} (gone)")
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for u, v in zip(a, b):
            compare(u, v, f"{path}[]", added, changed)
    elif a != b:
        changed.add(path)
same = True
for cmd in ("mc", "end-to-end"):
    runs = {(r[1], r[2]): r for r in rows if r[0] == cmd}
    # complete pairs only (a run cut short leaves its pair out)
    pairs = sorted({p for p, _ in runs if (p, "old") in runs and (p, "new") in runs}, key=int)
    print(f"{cmd}: {len(pairs)} pairs, ratio new/old")
    for i, name in ((3, "user CPU"), (4, "wall"), (5, "own throughput")):
        ratios = [float(runs[p, "new"][i]) / float(runs[p, "old"][i]) for p in pairs]
        print(f"  {name:15} median {statistics.median(ratios):.3f}  min {min(ratios):.3f}"
              f"  max {max(ratios):.3f}  ({' '.join(f'{r:.3f}' for r in ratios)})")
    loads = [float(r[6]) for r in runs.values()]
    print(f"  load average (1 min) at the runs' starts {min(loads):.1f}-{max(loads):.1f}")
    added, changed = set(), set()
    for p in pairs:
        compare(answer(f"{out}/{cmd}.{p}.old.json"), answer(f"{out}/{cmd}.{p}.new.json"),
                "", added, changed)
    if changed:
        same = False
        print(f"  answers differ in {sorted(changed)}")
    else:
        print("  every value the old binary writes is the same in the new one"
              + (f"; the new one adds {sorted(added)}" if added else ""))
print("answers identical apart from timings and added keys" if same else "ANSWERS DIFFER")
sys.exit(0 if same else 1)
EOF
