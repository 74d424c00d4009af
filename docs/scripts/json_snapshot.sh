#!/usr/bin/env bash
# Run every command with --json (or its machine output) on every shipped study; store outputs.
# Usage: json_snapshot.sh REPO OUTDIR [CLI...]   (CLI defaults to "cargo xtask")
set -u
repo=$1; out=$2; shift 2
cli=${*:-cargo xtask}
mkdir -p "$out"; cd "$repo"
run() { local name=$1; shift; echo "== $name" >&2; $cli "$@" > "$out/$name.json" 2> "$out/$name.err"; echo $? > "$out/$name.rc"; }
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
printf 'phi1_deg,phi2_deg,dphi_y1_arcmin,dphi_z2_arcmin,dalpha_x1_arcmin,dalpha_z1_arcmin,dalpha_x2_arcmin,dalpha_y2_arcmin,deps_x_arcmin,deps_y_arcmin,deta_mm\n10,20,0.4,0.7,0.4,0.7,0.28,0.28,0.42,0.42,1\n' > "$out/oe.csv"
$cli orientation-error --study studies/gyrowheel-2017.toml "$out/oe.csv" > "$out/orientation-error.csv" 2>"$out/orientation-error.err"
cut -d, -f3- "$out/oe.csv" > "$out/ce.csv"
$cli calibration-error --study studies/gyrowheel-2017.toml "$out/ce.csv" > "$out/calibration-error.csv" 2>"$out/calibration-error.err"
echo done >&2
