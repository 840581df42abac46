#!/usr/bin/env bash
# Sets up and runs every check: formatting, lints, the fuzz targets' build, the firmware builds
# (board and emulator, the board's memory budget), all host tests (core unit tests, oracles,
# CLI, the documented commands, recordings, property tests, the firmware on the emulated
# Cortex-M4 against the host bit for bit and in real time), and the core's instruction counts
# on the emulated Cortex-M4 against the stored baseline. Each step prints its time.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

started=$SECONDS
step_start=$SECONDS
step() {
  if [[ -n "${step_name:-}" ]]; then
    printf -- '-- %s: %d s\n' "$step_name" $((SECONDS - step_start))
  fi
  step_name="$*"
  step_start=$SECONDS
  printf '\n== %s\n' "$*"
}
trap 'step_name_end=$?; [[ -n "${step_name:-}" ]] && printf -- "-- %s: %d s\n" "$step_name" $((SECONDS - step_start)); printf "\n== %s after %d s\n" "$([[ $step_name_end == 0 ]] && echo passed || echo FAILED)" $((SECONDS - started))' EXIT

# The host tool and tests build with the `host-test` profile (release optimisation, no LTO:
# the same results, built in less time); every firmware with `release`, the profile that is
# flashed.
HOST=(--profile host-test)

step setup
scripts/setup.sh

step "cargo fmt --check"
cargo fmt --all --check

step "clippy (host crates and fuzz targets, all targets)"
cargo clippy --workspace --exclude impact-firmware --all-targets -- -D warnings

step "clippy (firmware: board, board + ADXL375, board + light gate, board + self-test, emulator, panic check, M4 bench)"
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --features adxl375 -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --features light-gate -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --features selftest -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features emulator -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features panic-check --bin panic-check -- -D warnings
cargo clippy --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features m4-bench --bin m4-bench -- -D warnings

step "cargo doc: every crate's docs (private items too) build without a warning, links resolved"
# Private items are documented (the docs are for the next engineer), so a link to one is fine.
export RUSTDOCFLAGS="-D warnings --document-private-items -A rustdoc::private-intra-doc-links"
cargo doc --no-deps "${HOST[@]}" -p impact-core -p impact-io -p impact-host
cargo doc --no-deps --release -p impact-firmware --target thumbv7em-none-eabihf
cargo doc --no-deps --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features emulator
unset RUSTDOCFLAGS

step "firmware: no reachable panic in the pipeline (links only if none survives optimization)"
cargo build --release -p impact-firmware --target thumbv7em-none-eabihf --no-default-features --features panic-check --bin panic-check

step "firmware: STM32F407VG release build (what cargo fw-run flashes)"
cargo fw

step "host tests (the documented commands, the emulated firmware against the host, real time)"
# tests/emulator.rs compares the emulated firmware with the host bit for bit; the tools were
# installed above, so a missing one is an error here, not a skip.
# tests/report.rs loads the HTML report in headless Chromium, also installed above.
IMPACT_REQUIRE_EMULATOR=1 IMPACT_REQUIRE_BROWSER=1 cargo test --workspace --exclude impact-firmware "${HOST[@]}"

step "Python package: pip install ./host-tests/python, its tests against the tool, the docs' Python examples"
# A virtual environment of the pinned test packages (made once: later runs need no network),
# the package built from this tree with maturin (the host-test profile: the tool's build
# above is reused), then pytest: every bundled recording analysed from Python equals
# `impact analyze --json` bit for bit (host-tests/python/tests), and docs/python.md's
# examples run as doctests.
target="${CARGO_TARGET_DIR:-target}"
venv="$target/python-venv"
# Made again when the pins change (the stamp holds their hash) or it does not work.
pins="$(sha256sum host-tests/python/requirements-test.txt | cut -d' ' -f1)"
if [[ "$(cat "$venv/pins" 2>/dev/null)" != "$pins" ]] \
  || ! "$venv/bin/python" -c 'import maturin, numpy, pandas, pytest, dask' 2>/dev/null; then
  rm -rf "$venv"
  python3 -m venv "$venv"
  "$venv/bin/pip" install --quiet --disable-pip-version-check -r host-tests/python/requirements-test.txt
  echo "$pins" > "$venv/pins"
fi
cargo build --quiet "${HOST[@]}" -p impact-host --bin impact
# (maturin's build hook runs the `maturin` the environment installed: its bin/ on the PATH.)
PATH="$(cd "$venv/bin" && pwd):$PATH" "$venv/bin/pip" install --quiet --disable-pip-version-check --no-build-isolation --no-deps --force-reinstall ./host-tests/python
IMPACT="$(cd "$target/host-test" && pwd)/impact" "$venv/bin/python" -m pytest -q -p no:cacheprovider \
  host-tests/python/tests docs/python.md --doctest-glob='*.md' -o doctest_optionflags='ELLIPSIS NORMALIZE_WHITESPACE'

step "golden outputs: the tool's outputs on scripts/golden.sh's commands, byte for byte (host-tests/golden)"
scripts/golden.sh --check

step "M4 instruction counts (QEMU, exact) against the stored baseline: fails on a > 10 % regression"
# Also checks the hand-written M4 routines against their portable versions and every f32
# solve on the M4 against the host's, bit for bit. Refresh the baseline after an intended
# change with: cargo run --release -p impact-host --bin impact -- bench m4 --json > host-tests/bench/m4-baseline.json
cargo run --quiet "${HOST[@]}" -p impact-host --bin impact -- bench m4 --check host-tests/bench/m4-baseline.json
