#!/usr/bin/env bash
# The tool's outputs on a fixed set of commands (every bundled recording and fixture in the
# modes a user runs; synth, simulate, emulate, log, report, watch's session and its exports),
# for refactors that must not change a byte: issue #48's check. Each command's stdout,
# stderr, exit status and written files go to OUT/, times and temporary paths normalised;
# OUT/SHA256SUMS lists them.
#
#   scripts/golden.sh OUT                 write the outputs (the tool: $IMPACT, else built)
#   scripts/golden.sh --check             write them to a temporary folder and compare with
#                                         host-tests/golden/SHA256SUMS (exit 1 on a difference,
#                                         each differing output named)
#
# host-tests/golden/SHA256SUMS was written at commit 496d474 (the start of #48). An intended
# change of an output refreshes it in the same commit, the output and the reason named there.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
root=$PWD

check=0
scratch=()
watch_pid=
trap '[[ -n "$watch_pid" ]] && kill "$watch_pid" 2>/dev/null; rm -rf "${scratch[@]}"' EXIT
if [[ "${1:-}" == "--check" ]]; then
  check=1
  out=$(mktemp -d)
  scratch+=("$out")
else
  out=${1:?usage: scripts/golden.sh OUT | --check}
  mkdir -p "$out"
  out=$(cd "$out" && pwd)
fi
# --check always checks the tool as the tree builds it now (cargo says where it is).
if [[ $check == 1 || -z "${IMPACT:-}" ]]; then
  IMPACT=$(cargo build --quiet --profile host-test -p impact-host --bin impact --message-format=json |
    sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1)
  [[ -x "$IMPACT" ]] || { echo "golden: the impact tool was not built" >&2; exit 1; }
fi

# The commands run in a scratch folder holding links to the bundled data, so that every path
# they print is the same wherever the repository lives.
work=$(mktemp -d)
scratch+=("$work")
ln -s "$root/host-tests/data" "$work/data"
ln -s "$root/host-tests/fixtures" "$work/fixtures"
ln -s "$root/host-tests/examples" "$work/examples"
ln -s "$root/docs" "$work/docs"
cd "$work"
# The reports' time (the reproducible-builds convention; their commit is normalised below).
export SOURCE_DATE_EPOCH=1764385620

# A path as a literal sed pattern.
literal() { printf '%s' "$1" | sed 's/[][\.*^$+?(){}|#/]/\\&/g'; }
work_re=$(literal "$work")
impact_re=$(literal "$IMPACT")
tmp_re=$(literal "${TMPDIR:-/tmp}")

# Times that vary from run to run, and the scratch folder's name.
normalise() {
  sed -E \
    -e "s#$work_re#WORK#g" \
    -e "s#$impact_re#impact#g" \
    -e "s#$tmp_re/impact-emulate-[^ :]+#TMP#g" \
    -e 's#127\.0\.0\.1:[0-9]+#127.0.0.1:PORT#g' \
    -e 's/(emulated in )[0-9.]+ s/\1T s/' \
    -e 's/(report_latency_s=)[0-9.e-]+/\1T/g' \
    -e 's/(busy_permille=|elapsed_ms=|stack_peak_bytes=)[0-9]+/\1T/g' \
    -e 's/(reported )[0-9.]+ (ms|s|µs)/\1T \2/g' \
    -e 's/^\[[0-9.:, ]+\]/[T]/' \
    -e 's/^[0-9]+\.[0-9]+ (TRACE|DEBUG|INFO|WARN|ERROR) /T \1 /' \
    -e 's/(busy )[0-9.]+ %/\1T %/g' \
    -e 's/(git commit )([0-9a-f]{40}|unknown)( with changes not committed \(a development build: not for a signed report\))?/\1COMMIT/g' \
    -e 's/(board.s session<\/td><td class="l">[^<]*<\/td><td>[0-9]+<\/td><td class="l hash">)[0-9a-f]{64}/\1HASH/' \
    -e 's/(stack )[0-9]+( of [0-9]+ B \()[0-9]+( %\))/\1T\2T\3/g' \
    -e '/^building the QEMU firmware/d' \
    "$1"
}

n=0
# run NAME ARGS…: the tool with ARGS; stdout, stderr and the exit status kept as NAME.*
run() {
  local name=$1
  shift
  n=$((n + 1))
  local rc=0
  "$IMPACT" "$@" >"$out/$name.stdout" 2>"$out/$name.stderr" </dev/null || rc=$?
  echo "$rc" >"$out/$name.exit"
  for f in "$out/$name.stdout" "$out/$name.stderr"; do
    normalise "$f" >"$f.n" && mv "$f.n" "$f"
  done
}
# keep FILE NAME: a file a command wrote, kept as NAME (text normalised, binary as it is)
keep() {
  if [[ -f "$1" ]]; then
    if grep -Iq . "$1"; then normalise "$1" >"$out/$2"; else cp "$1" "$out/$2"; fi
  else
    echo "missing" >"$out/$2"
  fi
}

recordings=(
  data/afrl-drop-tower/series1_test1_full_100ms.csv
  data/afrl-drop-tower/accel_5.csv
  data/afrl-drop-tower/accel_6.csv
  data/endaq-high-drop/High-Drop.IDE
  data/endaq-high-drop/High-Drop_16g-DC_full.csv
  data/endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv
  data/impack-water-entry/4mps_sphere_1_100g-PR_9.9-10.6s.csv
  data/impack-water-entry/4mps_sphere_1_40g-DC_9.9-10.6s.csv
  data/pyfrf-impact-hammer/measurement_1.csv
  data/pyfrf-impact-hammer/measurement_2.csv
  data/pyfrf-impact-hammer/measurement_3.csv
  data/pyfrf-impact-hammer/measurement_4.csv
  data/pyfrf-impact-hammer/measurement_5.csv
)
for r in "${recordings[@]}"; do
  b=$(basename "$r")
  run "analyze-$b" analyze "$r"
  run "analyze-$b-json" analyze "$r" --json
  run "analyze-$b-csv" analyze "$r" --csv
  run "analyze-$b-srs-cfc" analyze "$r" --srs --cfc 1000 --json
done
afrl=data/afrl-drop-tower/series1_test1_full_100ms.csv
run afrl-spec analyze "$afrl" --column bottom_kgn --spec half-sine,11000g,0.1ms
run afrl-spec-json analyze "$afrl" --column bottom_kgn --spec half-sine,11000g,0.1ms --json
run afrl-spec-csv analyze "$afrl" --column bottom_kgn --spec half-sine,11000g,0.1ms --csv
run afrl-axes analyze "$afrl" --axes bottom_kgn,top_kgn --csv
run afrl-scene analyze "$afrl" --scene examples/afrl-scene.json --json
run afrl-plot analyze "$afrl" --plot afrl.svg
keep afrl.svg afrl.svg
run afrl-png analyze "$afrl" --srs --plot afrl.png
keep afrl.png afrl.png
run series analyze data/afrl-drop-tower/accel_5.csv --channels 1,2,3,4,5 --units kgn
run series-json analyze data/afrl-drop-tower/accel_5.csv data/afrl-drop-tower/accel_6.csv --units kgn --json
run series-csv analyze data/afrl-drop-tower/accel_5.csv --channels 1,2,3,4,5 --units kgn --csv
run endaq-axes analyze data/endaq-high-drop/High-Drop_16g-DC_full.csv --axes x_g,y_g,z_g --json
run endaq-free-fall analyze data/endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv --column z_g --free-fall data/endaq-high-drop/High-Drop_16g-DC_full.csv
run endaq-units analyze data/endaq-high-drop/High-Drop_16g-DC_full.csv --units m/s2
run report report data/afrl-drop-tower/accel_5.csv --channels 1,2,3,4,5 --units kgn --spec half-sine,11000g,0.1ms --html afrl.html
keep afrl.html report.html
printf 'frequency_hz,acceleration_g\n10,1\n100,50\n10000,2000\n' >required.csv
run report-srs report "$afrl" --srs-required required.csv --html srs.html
keep srs.html report-srs.html
run report-ide report data/endaq-high-drop/High-Drop.IDE --html ide.html
keep ide.html report-ide.html

# Fixtures (the other formats).
run npy analyze fixtures/afrl-test1-int16.npy --rate 1e6 --json
run npy-f analyze fixtures/afrl-test1-float32-fortran.npy --rate 1e6 --column 1 --json
run wav analyze fixtures/afrl-test1-int16.wav --json
run wav-f analyze fixtures/afrl-test1-float32.wav --csv
run raw analyze fixtures/afrl-test1-2ch.i16 --rate 1e6 --raw-channels 2 --column 1 --gain 0.001 --json
run stream analyze "$afrl" --stream --range 20000g --trigger 2000g --json
run f32 analyze fixtures/afrl-test1.f32 --rate 1e6 --json
run tdms analyze fixtures/afrl-test1.tdms --column afrl/bottom_kgn --json

# Generated recordings: synth, then analysed.
run synth-seed synth --model two-phase --mass 0.06 --v0 1.3357 --max-deformation 0.0186 --kr 12376 --permanent 0.0182 --damping 2 -o seed.csv
keep seed.csv seed.csv
run seed analyze seed.csv --mass 0.06 --v0 1.3357
run seed-json analyze seed.csv --mass 0.06 --v0 1.3357 --json --srs
run seed-csv analyze seed.csv --mass 0.06 --v0 1.3357 --csv
run seed-plot analyze seed.csv --mass 0.06 --v0 1.3357 --plot seed.svg
keep seed.svg seed.svg
run synth-train synth --model nonlinear --mass 0.06 --v0 1.3357 --stiffness 1e4 --damping 0.5 --bounces 8 --duration 1.5 -o train.csv
keep train.csv train.csv
run train analyze train.csv --mass 0.06 --v0 1.3357 --train flight
run train-json analyze train.csv --mass 0.06 --v0 1.3357 --train flight --json
run train-csv analyze train.csv --mass 0.06 --v0 1.3357 --train flight --csv
run synth-hertz synth --model hertz --mass 0.06 --v0 1.3357 --stiffness 5e8 -o hertz.csv
keep hertz.csv hertz.csv
run synth-band synth --model linear --mass 0.06 --v0 1.716 --stiffness 4894 -o band.csv
keep band.csv band-pulse.csv
run band analyze band.csv --spec half-sine,50g,11ms,band-file=docs/bands/half-sine-50g-11ms.csv --json
run report-band report band.csv --spec half-sine,50g,11ms,band-file=docs/bands/half-sine-50g-11ms.csv --html band.html
keep band.html report-band.html
run synth-series synth --model two-phase --mass 0.06 --v0 1.3357 --max-deformation 0.0186 --kr 12376 --permanent 0.0182 --damping 2 --impacts 5 --every 0.08 --duration 0.42 -o seed-train.csv
keep seed-train.csv seed-train.csv

# Simulate: every model, text, JSON, figures.
run sim-hertz simulate --model hertz --mass 8.419e-3 --v0 2 --radius 6.35e-3 --youngs 200e9 --poisson 0.3
run sim-hertz-plot simulate --model hertz --mass 0.06 --v0 1.3357 --radius 0.0125 --youngs 2e11 --poisson 0.3 --plot hertz.svg --with-linear
keep hertz.svg sim-hertz.svg
run sim-target simulate --model hertz --mass 0.06 --v0 1.3357 --stiffness 5e8 --target-mass 0.3 --target-stiffness 4e4 --target-damping 12 --plot target.svg
keep target.svg sim-target.svg
run sim-linear simulate --model linear --mass 1 --v0 1 --stiffness 1e6 --target-mass 0.01 --target-stiffness 1e4 --json
run sim-kv simulate --model kelvin-voigt --mass 0.06 --v0 1.3357 --stiffness 2e5 --damping 8 --target examples/mount.json
run sim-two-phase simulate --model two-phase --mass 0.06 --v0 1.3357 --max-deformation 0.0186 --kr 12376 --permanent 0.0182 --damping 2 --json
run sim-nonlinear simulate --model nonlinear --mass 0.06 --v0 1.3357 --stiffness 1e4 --damping 0.5 --json

# Refusals: each message is an output too (the readers', the core's, the options').
run err-mass simulate --model linear --mass -1 --v0 1 --stiffness 1e6
run err-kr simulate --model two-phase --mass 0.06 --v0 1 --kc 1e5 --kr 1e4
run err-v0 synth --model linear --mass 0.06 --v0 -1 --stiffness 1e6
run err-target simulate --model linear --mass 1 --v0 1 --stiffness 1e6 --target-mass -1 --target-stiffness 1e4
printf 'time_s,accel_g\n' >empty.csv
run err-empty analyze empty.csv
printf 'time_s,accel_g\n0,1\n' >one.csv
run err-one analyze one.csv
IMPACT_READ_WHOLE=1 run err-one-whole analyze one.csv
run err-one-rate analyze one.csv --rate 1000
printf 'time_s,accel_g\n0,1\n1e-6,2\n0.5e-6,3\n3e-6,1\n4e-6,1\n' >back.csv
run err-back analyze back.csv
IMPACT_READ_WHOLE=1 run err-back-whole analyze back.csv
awk 'BEGIN{print "time_s,accel_g"; for(i=0;i<3000;i++){t=i*1e-6; if(i>=1500) t+=1e-6; printf "%.9f,%d\n", t, (i%7)-3}}' >gap.csv
run err-gap analyze gap.csv
IMPACT_READ_WHOLE=1 run err-gap-whole analyze gap.csv
awk 'BEGIN{print "time_s,accel_g"; t=0; for(i=0;i<5000;i++){t+=1e-6*(1+i/20000); printf "%.9f,%d\n", t, (i%7)-3}}' >drift.csv
run err-drift analyze drift.csv
IMPACT_READ_WHOLE=1 run err-drift-whole analyze drift.csv
printf 'time,accel\n0,1\n0.01,2\n0.02,1\n' >slow.csv
run err-slow analyze slow.csv
printf 'a,b\nx,y\n' >words.csv
run err-words analyze words.csv
run err-ide-rate analyze data/endaq-high-drop/High-Drop.IDE --rate 1000
run err-column analyze data/afrl-drop-tower/accel_5.csv --column nope
run err-units analyze data/endaq-high-drop/High-Drop_16g-DC_full.csv --units m/s2
run err-raw analyze fixtures/afrl-test1-2ch.i16
run err-raw-channels analyze fixtures/afrl-test1-2ch.i16 --rate 1e6 --raw-channels 65
run err-wav-rate analyze fixtures/afrl-test1-int16.wav --rate 1000
run err-npy-rate analyze fixtures/afrl-test1-int16.npy
run err-tdms-column analyze fixtures/afrl-test1.tdms --column nope
run err-missing analyze nothing-here.csv
run err-opt-mass analyze "$afrl" --mass abc
run err-opt-mass-range analyze "$afrl" --mass -1
run err-opt-rate analyze fixtures/afrl-test1.f32 --rate 0
run err-opt-cfc analyze "$afrl" --cfc 7
run err-opt-spec analyze "$afrl" --spec half-sine,11000,0.1
run err-opt-gain analyze "$afrl" --gain 0
printf 'frequency_hz,acceleration_g\n10,1\n5,2\n' >bad-srs.csv
run err-srs report "$afrl" --srs-required bad-srs.csv --html bad.html
printf 'time_s,lower_g\n0,1\n' >bad-band.csv
run err-band analyze "$afrl" --spec half-sine,50g,11ms,band-file=bad-band.csv

# The emulated board (when QEMU is here), its log read back, and the live view's session.
if command -v qemu-system-arm >/dev/null; then
  run emulate emulate seed.csv --mass 0.06 --v0 1.3357 --waveforms --log board.log
  keep board.log board.log
  run emulate-train emulate seed-train.csv --mass 0.06 --v0 1.3357 --v0-every --srs --spec half-sine,10g,3ms --log train.log
  keep train.log train.log
  run log-csv log board.log --csv
  run log-plain log board.log
  run log-json log board.log --json
  run log-plot log board.log --plot board.svg
  keep board.svg log-board.svg
  run log-export log board.log --export window.csv
  for f in window*.csv; do keep "$f" "log-export-$f"; done
  run log-train log train.log --json
  run watch watch board.log --terminal --once --session session.log
  keep session.log watch-session.log
  # The live view's exports, as its page serves them.
  "$IMPACT" watch board.log --once --listen 127.0.0.1:0 --session served.log >/dev/null 2>watch.err &
  watch_pid=$!
  port=
  for _ in $(seq 100); do
    port=$(sed -n 's#^impact watch: http://127\.0\.0\.1:\([0-9]*\)/.*#\1#p' watch.err)
    [[ -n "$port" ]] && curl -sf "http://127.0.0.1:$port/state.json" >/dev/null && break
    sleep 0.1
  done
  for path in session.json session.csv report.html; do
    curl -s "http://127.0.0.1:$port/$path" >"watch-$path" || true
    keep "watch-$path" "watch-export-$path"
  done
  kill "$watch_pid" 2>/dev/null || true
  wait "$watch_pid" 2>/dev/null || true
  watch_pid=
  run watch-train watch train.log --terminal --once --spec half-sine,10g,3ms --session train-session.log
  keep train-session.log watch-train-session.log
fi

cd "$out"
if [[ $check == 0 ]]; then
  sha256sum -- * | grep -v ' SHA256SUMS$' >SHA256SUMS
  echo "golden: $n commands, $(wc -l <SHA256SUMS) outputs in $out"
  exit 0
fi
sums="$root/host-tests/golden/SHA256SUMS"
if sha256sum --quiet -c "$sums" 2>/dev/null && [[ $(ls | wc -l) == $(wc -l <"$sums") ]]; then
  echo "golden: $n commands, $(wc -l <"$sums") outputs as host-tests/golden/SHA256SUMS lists them"
  exit 0
fi
echo "golden: outputs differ from host-tests/golden/SHA256SUMS:" >&2
sha256sum -c "$sums" 2>/dev/null | grep -v ': OK$' >&2 || true
comm -13 <(awk '{print $2}' "$sums" | sort) <(ls | sort) | sed 's/^/new output: /' >&2
exit 1
