"""A study CSV survives damage (issue 42, item 5): rows written by FrictionStudyFiles.appendCsv,
each with its Adler-32 check, read back by kfstudy.checked_csv. A row cut mid-field by a crash
and a row with bytes changed are each skipped and named (file, line); every whole row, before
and after them, is read; the next row appended after a cut one is whole."""
import zlib

from kfharness import sclang, sclang_session
from kfstudy import checked_csv

HEADER = ["participant", "answer", "level"]
# Free text with what CSV must quote: commas, quotes, new lines, and non-ASCII bytes.
ROWS = [["P1", "smooth, then \"sticky\"", "0.25"],
        ["P1", "two\nlines", "0.5"],
        ["P1", "rauh und glatt: ä", "1"]]


def append(path, rows):
    code = "".join(f"FrictionStudyFiles.appendCsv({sclang.sc_string(str(path))}, "
                   f"[{', '.join(sclang.sc_string(v) for v in row)}], {HEADER!r}.collect(_.asSymbol));\n"
                   .replace("'", "\"") for row in rows)
    sclang_session.run(code)


def as_dicts(rows):
    return [dict(zip(HEADER, row)) for row in rows]


def test_sclang_checks_rows_as_python_does(tmp_path):
    path = tmp_path / "answers.csv"
    append(path, ROWS)
    lines = path.read_bytes().split(b"\n")
    assert lines[0] == b"participant,answer,level,check"
    # The first row's bytes before its check field, and the check sclang wrote for them.
    body, check = lines[1].rsplit(b",", 1)
    assert check == b'"%08X"' % zlib.adler32(body)
    damaged = []
    assert checked_csv.read_rows(path, damaged) == as_dicts(ROWS) and damaged == []


def test_a_cut_row_and_a_changed_row_are_skipped_and_named(tmp_path):
    path = tmp_path / "answers.csv"
    append(path, ROWS[:2])
    whole = path.read_bytes()
    path.write_bytes(whole[:-20])  # the second row cut inside its level, as by a crash
    append(path, ROWS[2:])  # a resumed session's next answer
    text = path.read_bytes()
    assert text.count(b"\n") == 5  # header, row 1, the cut row (2 lines), the new row
    damaged = []
    assert checked_csv.read_rows(path, damaged) == as_dicts([ROWS[0], ROWS[2]])
    # The cut row's two lines: from its first, its quotes never close; its second alone has no check.
    assert [d.line for d in damaged] == [3, 4] and "quotes never close" in damaged[0].reason, damaged

    # A byte changed in the first row (garbage, a bad sector): that row alone is lost.
    path.write_bytes(text.replace(b"then", b"th\xffn", 1))
    damaged = []
    assert checked_csv.read_rows(path, damaged) == as_dicts([ROWS[2]])
    assert [(d.line, "check does not match" in d.reason) for d in damaged][0] == (2, True), damaged


def test_a_file_without_checks_is_read_as_plain_csv(tmp_path):
    path = tmp_path / "old.csv"
    path.write_bytes(b'participant,answer\n"P1","a\nb"\n"P2","\xff"\n')
    assert checked_csv.read_rows(path) == [{"participant": "P1", "answer": "a\nb"},
                                           {"participant": "P2", "answer": "\ufffd"}]


def sclang_reads(path):
    """FrictionStudyFiles.readCsv's rows (the answer field's bytes as hex) and damaged lines."""
    out = sclang_session.run(f"""
var damaged = List.new, rows = FrictionStudyFiles.readCsv({sclang.sc_string(str(path))}, damaged);
rows.do {{ |r| "KF-ROW % % % %".format(r[\\participant], r[\\answer].collectAs({{ |c| (c.ascii % 256).asHexString(2) }},
    Array).join, r[\\level], r.size).postln }};
"KF-DAMAGED %".format(damaged.join(" ")).postln;
""")
    rows = [line.split()[1:] for line in out.splitlines() if line.startswith("KF-ROW ")]
    damaged = [line.split()[1:] for line in out.splitlines() if line.startswith("KF-DAMAGED")]
    return [dict(participant=p, answer=bytes.fromhex(h).decode("utf-8"), level=level, size=int(n))
            for p, h, level, n in rows], [int(n) for n in damaged[0]]


def test_sclang_reads_what_python_reads_and_skips_the_same_lines(tmp_path):
    # A resume reads trials.csv and session.csv in sclang: the same rows and the same damaged
    # lines as kfstudy's report, on the cut and the changed rows above.
    path = tmp_path / "answers.csv"
    append(path, ROWS[:2])
    path.write_bytes(path.read_bytes()[:-20])
    append(path, ROWS[2:])
    rows, damaged = sclang_reads(path)
    assert [dict(r, size=None) for r in rows] == [dict(d, size=None) for d in as_dicts([ROWS[0], ROWS[2]])]
    assert {r["size"] for r in rows} == {len(HEADER)}  # the check column is left out
    assert damaged == [3, 4]
    path.write_bytes(path.read_bytes().replace(b"then", b"th\xffn", 1))
    rows, damaged = sclang_reads(path)
    assert [r["answer"] for r in rows] == [ROWS[2][1]] and damaged == [2, 3, 4]
    rows, damaged = sclang_reads(tmp_path / "none.csv")
    assert rows == [] and damaged == []
