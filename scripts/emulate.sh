#!/usr/bin/env bash
# Runs the impact-monitor firmware on QEMU's mps2-an386 (Cortex-M4F), replaying a file of
# raw little-endian i16 samples as if the ADC had sampled them, and decodes its defmt log.
#
#   scripts/emulate.sh [options] [SAMPLES_FILE] [KEY=VALUE ...]
#
# With no SAMPLES_FILE a 10000-sample demo signal is generated and replayed.
# KEY=VALUE arguments set the scene the monitor runs (unset keys keep the seed bench's:
# gain=0.390625 rate=500000 mass=0.06 v0=1.3357 trigger=10 edge=2 hold=0.002 max_impact=1
# clip=0:4095 cfc=none trigger_cfc=none two_phase=1 nonlinear=1 fit_exponent=1 exponent=1
# hertz=1; see firmware/README.md). `impact emulate` passes exactly the scene that
# `impact analyze` builds.
# The exit status is the firmware's (0: the stream was replayed and the run succeeded,
# 1: the firmware reported an error or crashed); 124 if the timeout expired, 2 for usage or
# setup errors.
#
# Options:
#   --realtime    real time: QEMU with an instruction-paced clock (-icount shift=3,sleep=off:
#                 8 ns of virtual time per instruction, standing for the STM32F407 at 168 MHz)
#                 and an emulated DMA writing the samples at the scene's rate whatever the
#                 firmware does; samples lost, analyses skipped and report latencies are in
#                 the log. Default: lossless (every sample reaches the firmware and every
#                 impact is analysed, at QEMU's own speed)
#   --rate-scale X  with --realtime: replay X times faster than the scene's rate
#   --lossless    the default (kept for old command lines)
#   --timeout S   stop QEMU after S seconds (default 120)
#   --no-build    use the ELF already built
#   --install     install the tools first: qemu-system-arm (apt-get) and defmt-print (cargo)
#   -h, --help    this text
#
# Needs: qemu-system-arm (Debian: qemu-system-arm), defmt-print (cargo install defmt-print),
# the thumbv7em-none-eabihf Rust target, python3 (only for the demo signal).
# The ELF is built into $CARGO_TARGET_DIR (default: target/) under
# thumbv7em-none-eabihf/release/impact-firmware, with the `emulator` feature instead of
# `stm32`. Paths may not contain spaces (semihosting passes arguments space-separated).

set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
TARGET=thumbv7em-none-eabihf
TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target}"
ELF="$TARGET_DIR/$TARGET/release/impact-firmware"

pacing=lossless
rate_scale=1
timeout_s=120
build=1
install=0
samples=""
scene=()

usage() { sed -n '2,/^$/{s/^# \{0,1\}//;p}' "${BASH_SOURCE[0]}"; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --lossless) pacing=lossless ;;
    --realtime) pacing=realtime ;;
    --rate-scale) rate_scale="${2:?--rate-scale needs a number}"; shift ;;
    --timeout) timeout_s="${2:?--timeout needs seconds}"; shift ;;
    --no-build) build=0 ;;
    --install) install=1 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "emulate.sh: unknown option $1" >&2; usage >&2; exit 2 ;;
    *=*) scene+=("$1") ;;
    *) [[ -z "$samples" ]] || { echo "emulate.sh: one samples file only" >&2; exit 2; }
       samples="$1" ;;
  esac
  shift
done

if [[ $install == 1 ]]; then
  if ! command -v qemu-system-arm >/dev/null; then
    sudo=""; [[ $(id -u) == 0 ]] || sudo="sudo"
    $sudo apt-get update
    $sudo apt-get install -y qemu-system-arm
  fi
  command -v defmt-print >/dev/null || cargo install defmt-print --locked
fi

missing=0
if ! command -v qemu-system-arm >/dev/null; then
  echo "emulate.sh: qemu-system-arm not found; install it with 'apt-get install qemu-system-arm'" \
       "or run scripts/emulate.sh --install" >&2
  missing=1
fi
if ! command -v defmt-print >/dev/null; then
  echo "emulate.sh: defmt-print not found; install it with 'cargo install defmt-print --locked'" \
       "or run scripts/emulate.sh --install" >&2
  missing=1
fi
[[ $missing == 0 ]] || exit 2

if [[ $build == 1 ]]; then
  # From the workspace root, so that .cargo/config.toml supplies the link arguments.
  (cd "$ROOT" && cargo build --release -p impact-firmware --target "$TARGET" \
     --no-default-features --features emulator)
fi
[[ -f "$ELF" ]] || { echo "emulate.sh: $ELF not built" >&2; exit 2; }

if [[ -z "$samples" ]]; then
  samples="$TARGET_DIR/emulator/demo-10000.i16"
  mkdir -p "$(dirname "$samples")"
  # 10000 samples: a 1000-count sine of period 100 samples with a 10-sample spike of +8000
  # at sample 5000. Replayed, the summary shows samples=10000 min=-1000 max=8536 sum=80000.
  python3 -c '
import math, struct, sys
s = [round(1000 * math.sin(2 * math.pi * i / 100)) + (8000 if 5000 <= i < 5010 else 0)
     for i in range(10000)]
sys.stdout.buffer.write(struct.pack("<%dh" % len(s), *s))' > "$samples"
  echo "emulate.sh: replaying generated demo signal $samples" >&2
fi
[[ -f "$samples" ]] || { echo "emulate.sh: no such samples file: $samples" >&2; exit 2; }
samples="$(cd "$(dirname "$samples")" && pwd)/$(basename "$samples")"
for arg in "$ELF" "$samples" "${scene[@]}"; do
  [[ "$arg" != *[[:space:],]* ]] || {
    echo "emulate.sh: argument contains a space or comma, which semihosting cannot pass: $arg" >&2
    exit 2
  }
done
config="enable=on,target=native,arg=$ELF,arg=$samples,arg=$pacing"
icount=()
if [[ $pacing == realtime ]]; then
  config+=",arg=rate_scale=$rate_scale"
  icount=(-icount shift=3,sleep=off)
fi
for kv in "${scene[@]}"; do config+=",arg=$kv"; done

# Semihosting output (the binary defmt stream) goes to QEMU's stdout; QEMU's own messages go
# to stderr. The semihosting command line is "<elf> <samples> <pacing> [key=value ...]".
set +e
timeout --foreground -k 5 "$timeout_s" \
  qemu-system-arm -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial null \
    "${icount[@]}" -semihosting-config "$config" \
    -kernel "$ELF" \
  | defmt-print -e "$ELF"
statuses=("${PIPESTATUS[@]}")
set -e

qemu_status=${statuses[0]}
if [[ $qemu_status == 124 ]]; then
  echo "emulate.sh: timed out after ${timeout_s}s" >&2
elif [[ ${statuses[1]} != 0 ]]; then
  echo "emulate.sh: defmt-print failed (status ${statuses[1]})" >&2
fi
exit "$qemu_status"
