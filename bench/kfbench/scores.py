"""The NRT parts' scores: sclang templates in sc/*.scd with @name@ placeholders (filled by
kfharness.sclang.fill), all written by one sclang run."""
from pathlib import Path

from kfharness import sclang

SC_DIR = Path(__file__).resolve().parent / "sc"


def code(name, **values):
    """sc/<name>.scd with its placeholders filled."""
    return sclang.fill((SC_DIR / f"{name}.scd").read_text(), **values)


def sc_path(path):
    return sclang.sc_string(path)


def write(bench, pieces):
    """Runs the score-writing pieces (each a `{ ... }.value;` block) in one sclang."""
    sclang.run_script("\n".join(pieces), timeout=300, include_paths=bench.include_paths, name="bench-scores")
