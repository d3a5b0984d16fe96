"""README.md's Python example runs as written (issue 27): every ```python block of the README,
in order, in a directory holding only what a fresh clone ships (the tracked files of `examples/`,
or the folder itself when git is not at hand), from that directory as its root, after
`mkdir -p out` as the README says. A block that raises, or that reads a file the clone does
not have, fails this test."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from conftest import ROOT


def python_blocks(text: str):
    """The ```python blocks of `text`: (first line number, body)."""
    blocks, body, start = [], None, 0
    for i, line in enumerate(text.splitlines(), start=1):
        if line.startswith("```"):
            if body is None:
                if line[3:].strip() == "python":
                    body, start = [], i + 1
            else:
                blocks.append((start, "\n".join(body) + "\n"))
                body = None
        elif body is not None:
            body.append(line)
    assert body is None, "README.md has an unclosed ```python block"
    return blocks


def shipped_examples(into: Path):
    """Copies the shipped `examples/` (git's tracked files, when git knows the checkout)."""
    try:
        listed = subprocess.run(
            ["git", "-C", str(ROOT), "ls-files", "-z", "examples"],
            capture_output=True, check=True,
        ).stdout.decode().split("\0")
        files = [f for f in listed if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
    if not files:
        shutil.copytree(ROOT / "examples", into / "examples")
        return
    for f in files:
        (into / f).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(ROOT / f, into / f)


def test_the_readme_python_example_runs_in_a_fresh_clone(tmp_path):
    blocks = python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))
    assert blocks, "README.md has no ```python block"
    shipped_examples(tmp_path)
    (tmp_path / "out").mkdir()
    for line, body in blocks:
        script = tmp_path / f"readme_line_{line}.py"
        script.write_text(body, encoding="utf-8")
        p = subprocess.run(
            [sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
            env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
        )
        assert p.returncode == 0, (
            f"README.md's ```python block at line {line} exited {p.returncode}:\n"
            f"--- stdout\n{p.stdout}--- stderr\n{p.stderr}"
        )
        print(f"README python block (line {line}) ran: {len(p.stdout.splitlines())} lines printed")
    # What the example says it writes is there.
    for written in ("out/ur5-py.json", "out/cell.csv", "out/cell.truth.json"):
        assert (tmp_path / written).is_file(), f"the README's Python example did not write {written}"
