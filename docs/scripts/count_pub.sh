#!/usr/bin/env bash
# Count `pub` items in library crates' src/ (not pub(crate), not tests/benches/examples).
# Usage: count_pub.sh DIR [crates...]
cd "$1"; shift
crates=${*:-$(ls -d */src | sed 's,/src,,' | grep -v -e xtask -e browser-check)}
printf "%-16s %6s %6s %6s %6s %6s %6s\n" crate fns types traits consts fields total
T=0
for c in $crates; do
  f=$(find $c/src -name '*.rs' | xargs cat)
  fns=$(grep -cE '^\s*pub (const )?(unsafe )?fn ' <<<"$f")
  types=$(grep -cE '^\s*pub (struct|enum|type) ' <<<"$f")
  traits=$(grep -cE '^\s*pub trait ' <<<"$f")
  consts=$(grep -cE '^\s*pub (const|static) [A-Z_0-9]+' <<<"$f")
  fields=$(grep -cE '^\s+pub [a-z_0-9]+: ' <<<"$f")
  tot=$((fns+types+traits+consts+fields)); T=$((T+tot))
  printf "%-16s %6d %6d %6d %6d %6d %6d\n" $c $fns $types $traits $consts $fields $tot
done
echo "total $T"
