"""python3 -m kfstudy SESSIONS REPORT: the report of the sessions in the folder SESSIONS (each a
folder FrictionStudy.run made) written into the folder REPORT (report.md, PNG figures, CSV files).
FrictionStudy.report runs it. The packages it needs are checked before anything is read: a missing
one is named with the Debian packages that hold them, and the exit status is 3."""
import importlib
import os
import sys

# Before numpy is imported: no huge pages on its arrays, whose collapse by the kernel's khugepaged
# holds a CPU for tens of ms where realtime threads wait (a report made while a session plays
# beside it; scripts/env.sh says more).
os.environ.setdefault("NUMPY_MADVISE_HUGEPAGE", "0")

# The module each needs, and its Debian package.
NEEDED = [("numpy", "python3-numpy"), ("pandas", "python3-pandas"), ("matplotlib", "python3-matplotlib"),
          ("scipy", "python3-scipy"), ("soundfile", "python3-soundfile")]
MISSING_STATUS = 3


def missing_packages():
    """[(module, Debian package, the import's error)] of the modules that do not import."""
    missing = []
    for module, package in NEEDED:
        try:
            importlib.import_module(module)
        except ImportError as error:
            missing.append((module, package, str(error)))
    return missing


def main(argv):
    if len(argv) != 2:
        print("usage: python3 -m kfstudy SESSIONS REPORT", file=sys.stderr)
        return 2
    missing = missing_packages()
    if missing:
        print("the study report needs python3 with " + ", ".join(m for m, _ in NEEDED) + "; missing: "
              + "; ".join(f"{m} ({error})" for m, _, error in missing) + ". On Debian or Ubuntu: sudo apt-get install "
              + " ".join(p for _, p in NEEDED), file=sys.stderr)
        return MISSING_STATUS
    from .report import write_report
    summary = write_report(argv[0], argv[1])
    print(f"{len(summary['sessions'])} sessions reported into {argv[1]}/report.md")
    for r in summary["binds"].to_dict("records"):
        print(f"binds, {r['mapping']}: off {r['mean_off']:.1f} mm/s, on {r['mean_on']:.1f} mm/s, "
              f"t({r['df']}) = {r['t']:.2f}, p = {r['p']:.3g}")
    for f in summary["thresholds"].to_dict("records"):
        print(f"threshold, {f['participant']} {f['condition']}: {f['threshold']:.4g} {f['unit']} "
              f"(model observer's {f['observer_threshold']:.4g}) from {f['trials']} trials")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
