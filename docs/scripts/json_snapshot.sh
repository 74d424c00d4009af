#!/usr/bin/env bash
# Run every command with --json (or its machine output) on every shipped study; store outputs.
# Usage: json_snapshot.sh REPO OUTDIR [CLI...]   (CLI defaults to "cargo xtask")
# SNAP_ONLY=REGEX runs only the runs whose name matches (grep -E), SNAP_SKIP=REGEX skips those
# that match, e.g. to redo one command's runs after a change:
# SNAP_ONLY='end-to-end|check' json_snapshot.sh . /tmp/after target/debug/ttalloc
# Fields that vary run to run (timings): `seconds`, `samples_per_sec`, `throughput`, the report's
# timing line; compare the rest byte for byte (diff -r).
set -u
repo=$1; out=$2; shift 2
cli=${*:-cargo xtask}
only=${SNAP_ONLY:-.}
skip=${SNAP_SKIP:-^$}
mkdir -p "$out"; cd "$repo"
run() {
  local name=$1; shift
  echo "$name" | grep -Eq -- "$only" || return 0
  echo "$name" | grep -Eq -- "$skip" && return 0
  echo "== $name" >&2; $cli "$@" > "$out/$name.json" 2> "$out/$name.err"; echo $? > "$out/$name.rc"
}
for s in gyrowheel-2017 three-axis-example imu-triad-example; do
  st=studies/$s.toml
  run $s.requirement requirement --study $st --json
  run $s.requirement-all requirement --study $st --json --all-readings
  run $s.allocate allocate --study $st --json
  run $s.mc mc --study $st --json --samples 100000
  run $s.end-to-end end-to-end --study $st --json --samples 2000
  run $s.design-schedule design-schedule --study $st --json
  run $s.report report --study $st --samples 2000 --out "$out/$s.report"
done
run gyrowheel-2017.check check-turntable --study studies/gyrowheel-2017.toml --tolerances studies/tolerances/table4.toml --json --samples 2000
run three-axis.check check-turntable --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-navigation-grade.toml --json --samples 2000
run gyrowheel-2017.mc-table4 mc --study studies/gyrowheel-2017.toml --json --samples 100000 --bounds table4
# the studies with noise, angle-dependent errors, measured errors, rate steps
for s in gyrowheel-2017-noise-assumed gyrowheel-2017-harmonic-errors three-axis-example-compensated tactical-rate-table-example; do
  st=studies/$s.toml
  run $s.allocate allocate --study $st --json
  run $s.end-to-end end-to-end --study $st --json --samples 2000
  run $s.report report --study $st --samples 2000 --out "$out/$s.report"
done
run gyrowheel-2017-noise-assumed.check check-turntable --study studies/gyrowheel-2017-noise-assumed.toml --tolerances studies/tolerances/table4.toml --json --samples 2000
run gyrowheel-2017-harmonic-errors.check check-turntable --study studies/gyrowheel-2017-harmonic-errors.toml --tolerances studies/tolerances/table4.toml --json --samples 2000
run three-axis-compensated.check check-turntable --study studies/three-axis-example-compensated.toml --tolerances studies/tolerances/three-axis-vendor-sheet.toml --json --samples 2000
run tactical-rate-table.check check-turntable --study studies/tactical-rate-table-example.toml --tolerances studies/tolerances/tactical-rate-table-sheet.toml --json --samples 2000
# results.json with a vendor's sheet (vendor, its rate steps) and the paper's report (claims)
run three-axis.report-sheet report --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-vendor-sheet.toml --samples 2000 --out "$out/three-axis.report-sheet"
run tactical-rate-table.report-sheet report --study studies/tactical-rate-table-example.toml --tolerances studies/tolerances/tactical-rate-table-sheet.toml --samples 2000 --out "$out/tactical-rate-table.report-sheet"
run reproduce-paper reproduce-paper --samples 2000 --out "$out/reproduce-paper"
# a vendor sheet's pairs (disc_allocation), the estimable errors, the Monte Carlo over a sheet
run gyrowheel-2017.allocate-sheet allocate --study studies/gyrowheel-2017.toml --tolerances studies/tolerances/table4.toml --json
run three-axis.allocate-sheet allocate --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-vendor-sheet.toml --json
run three-axis.end-to-end-sheet end-to-end --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-vendor-sheet.toml --json --samples 2000
run three-axis.mc-sheet mc --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-navigation-grade.toml --json --samples 100000
for s in gyrowheel-2017 three-axis-example imu-triad-example tactical-rate-table-example; do
  run $s.estimable estimable --study studies/$s.toml --json
done
run three-axis.estimable-sheet estimable --study studies/three-axis-example.toml --tolerances studies/tolerances/three-axis-vendor-sheet.toml --json
# schedule design with noise under a time budget, and the rate steps' rates (slow: once each)
run gyrowheel-2017-noise-assumed.design-schedule-budget design-schedule --study studies/gyrowheel-2017-noise-assumed.toml --time-budget-s 1800 --json
run gyrowheel-2017.design-schedule-budget-noiseless design-schedule --study studies/gyrowheel-2017.toml --time-budget-s 1800 --json
run tactical-rate-table.design-schedule-rates design-schedule --study studies/tactical-rate-table-example.toml --step-deg 90 --rates-deg-per-s 20,60 --json
# noise from a log (a seeded pseudo-random log: no study)
awk 'BEGIN { x = 12345; print "t_s,gz_deg_per_s"; for (i = 0; i < 20000; i++) { s = 0; for (k = 0; k < 12; k++) { x = (1103515245 * x + 12345) % 2147483648; s += x / 2147483648 } printf "%.4f,%.9f\n", i / 100, 0.01 * (s - 6) + 1e-6 * i } }' > "$out/allan-log.csv"
run allan allan "$out/allan-log.csv" --rate-hz 100 --column gz_deg_per_s --json
printf 'phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm\n10,20,0.4,0.7,0.4,0.7,0.28,0.28,0.42,0.42,1\n' > "$out/oe.csv"
$cli orientation-error --study studies/gyrowheel-2017.toml "$out/oe.csv" > "$out/orientation-error.csv" 2>"$out/orientation-error.err"
cut -d, -f3- "$out/oe.csv" > "$out/ce.csv"
$cli calibration-error --study studies/gyrowheel-2017.toml "$out/ce.csv" > "$out/calibration-error.csv" 2>"$out/calibration-error.err"
echo done >&2
