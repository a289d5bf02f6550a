"""scripts/gallery.sh, the README's pattern gallery: every pattern rendered on the simulated
device at a slow and a fast speed, a CSV and a PNG each, and the summary with the anti-aliasing
and steering figures (issue 27), into KF_GALLERY_OUT."""
import csv
import os
import re
import shutil
import subprocess
from pathlib import Path

from kfharness import paths

OUT = Path(os.environ.get("KF_GALLERY_OUT") or paths.work_dir() / "gallery")


def test_the_gallery_renders_every_pattern_with_its_figures():
    shutil.rmtree(OUT, ignore_errors=True)
    run = subprocess.run(["bash", str(paths.REPO_DIR / "scripts" / "gallery.sh"), "--out", str(OUT)],
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=840)
    assert run.returncode == 0, run.stdout[-4000:]
    summary = (OUT / "summary.md").read_text()
    rows = re.findall(r"^\| ([\w-]+) \| (slow|fast) \|", summary, re.M)
    names = {name for name, _ in rows}
    for kind in ("grating", "bumps", "valleys", "detents", "texture", "texture2D-along-x", "viscous", "stick-slip"):
        assert kind in names, f"{kind} not in the gallery's summary"
    for name, speed in rows:
        for suffix in (".csv", ".png"):
            path = OUT / f"{name}-{speed}{suffix}"
            assert path.is_file() and path.stat().st_size > 0, f"{path.name} missing or empty"
        with open(OUT / f"{name}-{speed}.csv") as f:
            table = list(csv.DictReader(f))
        # The pilot's writer: no row after the scene, so never the render's all-zero tail.
        last = table[-1]
        assert float(last["force_commanded_n"]) >= 0.14 - 1e-6, f"{name}-{speed}.csv ends below the minimum force"
    # bumps2D's fine grid at 300 mm/s: no alias anti-aliased (its mean; float rounding ~2e-8 N),
    # an alias raw (> 0.01 N: the figure shows one).
    grid = re.findall(r"^\| (along x|along y|at 30 degrees) \| ([\d.e+-]+) \| ([\d.e+-]+) \|$", summary, re.M)
    assert len(grid) == 3, "bumps2D's alias figures not in the summary"
    for path, on, raw in grid:
        assert float(on) < 1e-6 and float(raw) > 0.01, f"bumps2D {path}: {on} N anti-aliased, {raw} N raw"
    for section in ("## Anti-aliasing in space", "## Friction that steers", "## 2D surfaces", "## The 2D texture"):
        assert section in summary, f"no \"{section}\" in the summary"
    for name in ("texture2D-raster.csv", "texture2D-raster.png"):
        assert (OUT / name).is_file() and (OUT / name).stat().st_size > 0, f"{name} missing or empty"
    # The raster's force against the definition recomputed from the rendered (x, y): float rounding
    # of the force (0.5 N * 2^-24 = 3e-8 N) is all that may differ (measured 1.5e-8 N).
    texture = re.search(r"largest deviation from the definition .*?: ([\d.e+-]+) N", summary)
    assert texture and float(texture.group(1)) < 1e-6, f"texture2D raster deviation: {texture and texture.group(1)}"
