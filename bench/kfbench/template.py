"""The report's prose: bench/REPORT.md.in holds named blocks (a line `@@ name` starts one), each
text with str.format fields that the code fills with numbers and tables."""
import functools

from .common import BENCH_DIR

TEMPLATE_PATH = BENCH_DIR / "REPORT.md.in"


@functools.lru_cache(maxsize=None)
def blocks():
    out, name, lines = {}, None, []
    for line in TEMPLATE_PATH.read_text().splitlines():
        if line.startswith("@@ "):
            if name:
                out[name] = "\n".join(lines).strip("\n")
            name, lines = line[3:].strip(), []
        elif name:
            lines.append(line)
    if name:
        out[name] = "\n".join(lines).strip("\n")
    return out


def render(name, **fields):
    return blocks()[name].format(**fields)
