#!/usr/bin/env bash
# CI of the Python bindings: builds the `robocal` package (maturin, release) into a virtual
# environment under the cargo target directory and runs its pytest suite.
#
#   bash crates/robocal-py/ci.sh
#
# Exit status: 0 the suite passed; 1 the build or a test failed; 77 skipped, with the reason on
# the last line (no python3 or venv module, or maturin, numpy and pytest not available).
# Where: $CARGO_TARGET_DIR/python-ci (default target/python-ci): the venv there is reused when it
# has maturin, numpy and pytest; the wheel is built into the same target directory (nothing
# else inside the clone). Network: none unless asked. Without a usable venv the packages are
# installed with `pip --no-index` (from PIP_FIND_LINKS, a folder of wheels, if set); with
# ROBOCAL_PY_ONLINE=1 pip may reach PyPI. ROBOCAL_BIN names the robocal CLI the suite compares
# against (default: the target directory's release/robocal); ROBOCAL_REAL_DATA the folder of the
# real data sets (default: ../shared/data beside the checkout).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
target="${CARGO_TARGET_DIR:-$root/target}"
case "$target" in /*) ;; *) target="$root/$target" ;; esac
work="$target/python-ci"
venv="$work/venv"

skip() {
  echo "python-ci: skipped: $*"
  exit 77
}

command -v python3 >/dev/null 2>&1 || skip "python3 not found"
python3 -c 'import venv, ensurepip' >/dev/null 2>&1 || skip "python3 has no venv/ensurepip module (Debian: apt-get install python3-venv)"

mkdir -p "$work"
rm -rf "$work/wheels"
py="$venv/bin/python"
ready() { [ -x "$py" ] && "$py" -c 'import maturin, numpy, pytest' >/dev/null 2>&1; }
if ready; then
  echo "python-ci: reusing $venv (maturin, numpy and pytest present)"
else
  rm -rf "$venv"
  python3 -m venv "$venv" || skip "python3 -m venv failed"
  if [ "${ROBOCAL_PY_ONLINE:-0}" = 1 ]; then
    echo "python-ci: installing maturin, numpy, pytest into $venv from PyPI (ROBOCAL_PY_ONLINE=1)"
    index=()
  else
    echo "python-ci: installing maturin, numpy, pytest into $venv without the network (pip --no-index${PIP_FIND_LINKS:+, wheels from $PIP_FIND_LINKS})"
    index=(--no-index)
  fi
  if ! "$py" -m pip install --disable-pip-version-check -q "${index[@]}" "maturin>=1.5,<2" numpy pytest >"$work/pip.log" 2>&1; then
    tail -5 "$work/pip.log"
    if [ "${ROBOCAL_PY_ONLINE:-0}" = 1 ]; then
      skip "pip could not install maturin, numpy and pytest (is PyPI reachable? see $work/pip.log)"
    fi
    skip "maturin, numpy and pytest are not available offline: set ROBOCAL_PY_ONLINE=1 to let pip reach PyPI, or PIP_FIND_LINKS to a folder of their wheels"
  fi
fi

echo "python-ci: building the wheel (maturin build --release; about 5 minutes on 2 cores from scratch, cargo's progress below)"
start=$(date +%s)
if ! (cd "$here" && VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$target" \
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

export ROBOCAL_BIN="${ROBOCAL_BIN:-$target/release/robocal}"
export ROBOCAL_ROOT="$root"
# The tests run against the installed wheel, not the source folder.
cd "$work" || exit 1
"$py" -m pytest -q -s -rs -p no:cacheprovider "$here/tests"
rc=$?
if [ "$rc" -ne 0 ]; then
  echo "python-ci: FAILED: pytest exited with $rc"
  exit 1
fi
