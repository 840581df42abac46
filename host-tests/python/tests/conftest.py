"""The package's tests compare it with the `impact` tool built from the same tree.

The tool is `$IMPACT` if set (scripts/test.sh sets it), else the host-test build in the
workspace's target directory (`cargo build --profile host-test -p impact-host --bin impact`).
"""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
DATA = ROOT / "host-tests" / "data"


def _tool() -> pathlib.Path:
    given = os.environ.get("IMPACT")
    if given:
        return pathlib.Path(given)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return target / "host-test" / "impact"


@pytest.fixture(scope="session")
def tool() -> pathlib.Path:
    path = _tool()
    if not path.is_file():
        pytest.fail(f"the impact tool is not built at {path}: build it or set IMPACT")
    return path


class Cli:
    """The tool run as a user runs it: its JSON, notes and exit status."""

    def __init__(self, tool: pathlib.Path):
        self.tool = tool

    def run(self, *args: str) -> subprocess.CompletedProcess:
        return subprocess.run([str(self.tool), *map(str, args)], capture_output=True, text=True, cwd=ROOT)

    def json(self, *args: str) -> dict:
        return self.analysis(*args)[0]

    def analysis(self, *args: str):
        """The JSON and the notes (stderr's `note: ` lines, in order)."""
        p = self.run(*args, "--json")
        # 0: done; 3: done, a judged impact failed its spec (a result).
        assert p.returncode in (0, 3), p.stderr
        notes = [l[len("note: "):] for l in p.stderr.splitlines() if l.startswith("note: ")]
        return json.loads(p.stdout), notes


@pytest.fixture(scope="session")
def cli(tool) -> Cli:
    return Cli(tool)


def recordings() -> list:
    """Every bundled recording (host-tests/data, each with its PROVENANCE)."""
    return sorted(p for p in DATA.rglob("*") if p.is_file() and p.name != "PROVENANCE")
