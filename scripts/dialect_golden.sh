#!/bin/bash
# Writes the programs (and the errors and exit codes) of every fixture on every machine in every
# dialect, with and without a technology, plus micro-joints and the controller's kerf
# compensation, into OUT: run it before and after a change of the G-code writer and compare
# with `diff -r BEFORE AFTER` (the writer's refactor into one file per dialect changed no byte).
#   cargo build --release -p kerf-cli && scripts/dialect_golden.sh /tmp/before
set -u
OUT=$(realpath -m "$1"); mkdir -p "$OUT"; cd "$(dirname "$0")/.."
K=./target/release/kerf
TECH="--technology fixtures/technology/fiber_3kw_example.json --material stainless --thickness 2"
for f in fixtures/*.json; do n=$(basename $f .json)
 for m in fixtures/machines/*.json; do mn=$(basename $m .json)
  for d in generic sinumerik linuxcnc linuxcnc-tcp fanuc fanuc-ijk heidenhain heidenhain-axes; do
   for v in plain tech; do
    extra=""; [ $v = tech ] && extra="$TECH"
    o="$OUT"/$n-$mn-$d-$v; $K run $f -m $m --dialect $d -o $o -q $extra >/dev/null 2>$o.err; echo $? > $o.rc
    rm -f $o/plot.svg $o/report.json
   done
  done
 done
done
# micro-joints and kerf in control on the flat part
for d in generic linuxcnc linuxcnc-tcp; do $K run fixtures/sheet_metal_holes.json -m fixtures/machines/gantry_ac.json --dialect $d --micro-joints 0.5,40 -o "$OUT"/mj-$d -q 2>"$OUT"/mj-$d.err; echo $? > "$OUT"/mj-$d.rc; done
$K run fixtures/sheet_metal_holes.json -m fixtures/machines/gantry_ac.json --dialect linuxcnc --kerf-width 0.2 --kerf-in-control -o "$OUT"/kic -q 2>"$OUT"/kic.err; echo $? > "$OUT"/kic.rc
$K run fixtures/sheet_metal_holes.json -m fixtures/machines/gantry_ac.json --dialect sinumerik --kerf-width 0.2 --kerf-in-control -o "$OUT"/kic-sinumerik -q 2>"$OUT"/kic-sinumerik.err; echo $? > "$OUT"/kic-sinumerik.rc
$K run fixtures/sheet_metal_holes.json -m fixtures/machines/xyzac_trt.json --dialect linuxcnc-tcp --micro-joints 0.5,40 $TECH -o "$OUT"/mj-tcp-tech -q 2>"$OUT"/mj-tcp-tech.err; echo $? > "$OUT"/mj-tcp-tech.rc
find $OUT -name report.json -delete; find $OUT -name plot.svg -delete
