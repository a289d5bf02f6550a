"""The study's CSV files read row by row, each row checked (FrictionStudyFiles.appendCsv writes them).

Every row a session writes ends with a field `check`: the Adler-32 (RFC 1950, zlib.adler32) of
the row's bytes before it, as 8 hex digits. A row cut by a crash or a full disk, or with bytes
changed, fails its check; it is reported (file, line, why) and skipped, and the rows after it are
read. A row may span lines (free text keeps its new lines inside quotes), so a record is the
shortest run of lines from a row's start with balanced quotes; a damaged one that never balances
(a row cut inside a quoted field) costs only its own first line: the next line is tried as a
row's start. Files without a check column (written before it) are read as plain CSV."""
import csv
import io
import zlib
from dataclasses import dataclass
from pathlib import Path

CHECK_FIELD = "check"
CHECK_DIGITS = 8
MAX_ROW_LINES = 64  # a row's free text spans at most this many lines


@dataclass
class DamagedRow:
    path: Path
    line: int  # 1-based, as an editor shows it
    reason: str

    def __str__(self):
        return f"{self.path.name} line {self.line}: {self.reason}"


def row_check(body):
    """The check field's value for a row's bytes before it."""
    return f"{zlib.adler32(body):0{CHECK_DIGITS}X}"


def _checked_row(record, width):
    """(fields, None) of a record whose check holds, else (None, why)."""
    tail = len(f',"{"0" * CHECK_DIGITS}"')
    body, check = record[:-tail], record[-tail:]
    if not (check.startswith(b',"') and check.endswith(b'"')):
        return None, "no check field at its end (cut short?)"
    if row_check(body) != check[2:-1].decode("ascii", errors="replace").upper():
        return None, "its check does not match its bytes (cut or changed)"
    try:
        fields = next(csv.reader(io.StringIO(body.decode("utf-8"), newline="")))
    except (UnicodeDecodeError, StopIteration, csv.Error) as error:
        return None, f"unreadable ({error})"
    if len(fields) != width:
        return None, f"{len(fields)} fields where the header has {width}"
    return fields, None


def read_rows(path, damaged=None):
    """The rows of a study CSV as dicts (the check column left out). Each damaged row is skipped
    and appended to `damaged` (a list) as a DamagedRow."""
    path = Path(path)
    data = path.read_bytes()
    lines = data.split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    if not lines:
        return []
    header = next(csv.reader([lines[0].decode("utf-8", errors="replace")]), [])
    if not header or header[-1] != CHECK_FIELD:
        text = b"\n".join(lines).decode("utf-8", errors="replace")
        return list(csv.DictReader(io.StringIO(text, newline="")))
    names = header[:-1]
    rows, start = [], 1
    while start < len(lines):
        why = "its quotes never close (cut inside a field)"
        for end in range(start, min(start + MAX_ROW_LINES, len(lines))):
            record = b"\n".join(lines[start:end + 1])
            if record.count(b'"') % 2 == 0:
                fields, why = _checked_row(record, len(names))
                if fields is not None:
                    rows.append(dict(zip(names, fields)))
                    start = end + 1
                break
        if why is not None:
            if damaged is not None:
                damaged.append(DamagedRow(path, start + 1, why))
            start += 1
    return rows
