#!/usr/bin/env bash
# Installs what the project needs beyond a Rust toolchain, idempotently:
#   - the Cortex-M4F Rust target (thumbv7em-none-eabihf), rustfmt and clippy;
#   - qemu-system-arm (Debian package) for the emulated firmware;
#   - arm-none-eabi-objdump (Debian binutils-arm-none-eabi) for `impact bench m4`'s cycle model;
#   - chromium (Debian package) for the HTML report's test in a real headless browser and for
#     `impact report --pdf`; poppler-utils (pdftoppm, pdfinfo) for the PDF's test;
#   - python3 with its venv module (Debian python3-venv) for the Python package's tests.
# With --board, also probe-rs (crates.io `probe-rs-tools`, a few minutes to build) to flash
# the STM32F4-Discovery and read its defmt log (`cargo fw-run`).
# Run as root or with sudo available for apt-get.
set -euo pipefail

board=0
for arg in "$@"; do
  case "$arg" in
    --board) board=1 ;;
    -h|--help) sed -n '2,/^set -e/{s/^# \{0,1\}//;/^set -e/d;p}' "${BASH_SOURCE[0]}"; exit 0 ;;
    *) echo "setup.sh: unknown option $arg" >&2; exit 2 ;;
  esac
done

need_apt=()
command -v qemu-system-arm >/dev/null || need_apt+=(qemu-system-arm)
command -v arm-none-eabi-size >/dev/null || need_apt+=(binutils-arm-none-eabi)
command -v chromium >/dev/null || need_apt+=(chromium)
command -v pdftoppm >/dev/null || need_apt+=(poppler-utils)
python3 -c 'import venv, ensurepip' 2>/dev/null || need_apt+=(python3-venv)
if [[ ${#need_apt[@]} -gt 0 ]]; then
  sudo=""; [[ $(id -u) == 0 ]] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

rustup target list --installed | grep -qx thumbv7em-none-eabihf || rustup target add thumbv7em-none-eabihf
rustup component list --installed | grep -q '^rustfmt' || rustup component add rustfmt
rustup component list --installed | grep -q '^clippy' || rustup component add clippy

if [[ $board == 1 ]]; then
  # probe-rs needs libudev to find USB probes.
  if ! dpkg -s libudev-dev >/dev/null 2>&1; then
    sudo=""; [[ $(id -u) == 0 ]] || sudo="sudo"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq libudev-dev pkg-config >/dev/null
  fi
  command -v probe-rs >/dev/null || cargo install probe-rs-tools --locked --quiet
fi
