#!/usr/bin/env bash
# CI of the Python bindings: builds the `robocal` package (maturin, release) into a fresh
# virtual environment under target/ and runs its pytest suite.
#
#   bash crates/robocal-py/ci.sh
#
# Exit status: 0 the suite passed; 1 the build or a test failed; 77 skipped, with the reason on
# the last line (no python3 or venv module, or PyPI unreachable while installing maturin, numpy
# and pytest). ROBOCAL_BIN names the robocal CLI the suite compares against (default:
# target/release/robocal); ROBOCAL_REAL_DATA the folder of the real data sets (default:
# ../shared/data beside the checkout).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
work="$root/target/python-ci"
venv="$work/venv"

skip() {
  echo "python-ci: skipped: $*"
  exit 77
}

command -v python3 >/dev/null 2>&1 || skip "python3 not found"
python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || skip "python3 has no venv/ensurepip module (Debian: apt-get install python3-venv)"

rm -rf "$venv" "$work/wheels"
mkdir -p "$work"
python3 -m venv "$venv" || skip "python3 -m venv failed"
py="$venv/bin/python"

echo "python-ci: installing maturin, numpy, pytest into $venv"
if ! "$py" -m pip install --disable-pip-version-check -q "maturin>=1.5,<2" numpy pytest >"$work/pip.log" 2>&1; then
  tail -5 "$work/pip.log"
  skip "pip could not install maturin, numpy and pytest (is PyPI reachable? see $work/pip.log)"
fi

echo "python-ci: building the wheel (maturin build --release)"
start=$(date +%s)
if ! (cd "$here" && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$root/target" \
  "$venv/bin/maturin" build --release --interpreter "$py" --out "$work/wheels"); then
  echo "python-ci: FAILED: the build failed"
  exit 1
fi
echo "python-ci: wheel built in $(($(date +%s) - start)) s"
wheel=$(ls "$work"/wheels/robocal-*.whl | head -1)
if ! "$py" -m pip install --disable-pip-version-check -q --no-deps --force-reinstall "$wheel"; then
  echo "python-ci: FAILED: the wheel $wheel does not install"
  exit 1
fi

export ROBOCAL_BIN="${ROBOCAL_BIN:-$root/target/release/robocal}"
export ROBOCAL_ROOT="$root"
# The tests run against the installed wheel, not the source folder.
cd "$work" || exit 1
"$py" -m pytest -q -s -rs -p no:cacheprovider "$here/tests"
rc=$?
if [ "$rc" -ne 0 ]; then
  echo "python-ci: FAILED: pytest exited with $rc"
  exit 1
fi
