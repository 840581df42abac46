#!/usr/bin/env bash
# Sets up and runs every check: formatting, lints, all host tests (core unit tests,
# oracles, CLI, recordings, property tests), both firmware builds (board and emulator)
# with their flash/RAM use, the firmware on the emulated Cortex-M4, and the core's
# instruction counts on the emulated Cortex-M4 against the stored baseline.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

step() { printf '\n== %s\n' "$*"; }

step setup
scripts/setup.sh

step "cargo fmt --check"
cargo fmt --all --check

step "clippy (host crates, all targets)"
cargo clippy --workspace --exclude impact-firmware --all-targets -- -D warnings

step "clippy (firmware: board, board + ADXL375, board + light gate, emulator, panic check)"
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --features adxl375 -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --features light-gate -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features emulator -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features panic-check --bin panic-check -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features m4-bench --bin m4-bench -- -D warnings

step "firmware: no reachable panic in the pipeline (links only if none survives optimization)"
cargo build --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features panic-check --bin panic-check

step "firmware: STM32F407VG release build"
cargo build --release -p impact-firmware --target thumbv7em-none-eabihf
arm-none-eabi-size target/thumbv7em-none-eabihf/release/impact-firmware

step "firmware: emulator (mps2-an386) release build, run on QEMU"
scripts/emulate.sh --lossless --timeout 120
arm-none-eabi-size target/thumbv7em-none-eabihf/release/impact-firmware

step "M4 instruction counts (QEMU, exact) against the stored baseline: fails on a > 10 % regression"
# Also checks the hand-written M4 routines against their portable versions and every f32
# solve on the M4 against the host's, bit for bit. Refresh the baseline after an intended
# change with: cargo run --release -p impact-host --bin impact -- bench m4 --json > host-tests/bench/m4-baseline.json
cargo run --release --quiet -p impact-host --bin impact -- bench m4 --check host-tests/bench/m4-baseline.json

step "host tests (release: the oracle and recording tests are numerically heavy)"
# tests/emulator.rs compares the emulated firmware with the host bit for bit; the tools were
# installed above, so a missing one is an error here, not a skip.
IMPACT_REQUIRE_EMULATOR=1 cargo test --workspace --exclude impact-firmware --release
