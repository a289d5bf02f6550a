"""The tests' reading of a study's BIDS folder (kfstudy.bids) as a researcher's pandas would:
every table's columns are the ones its JSON sidecar describes, in order; a column with Levels
holds only those; a column with Units holds numbers; "n/a" is the only missing value."""
import json
from pathlib import Path


def sidecar_of(tsv):
    """The sidecar that describes a table: its own .json, else the folder's (participants.json,
    counts.json for the derivatives' counts)."""
    own = tsv.with_suffix(".json")
    if own.exists():
        return own
    if tsv.name.endswith("_counts.tsv"):
        return tsv.parent / "counts.json"
    raise AssertionError(f"{tsv}: no sidecar describes it")


def read_checked(folder):
    """{path relative to folder: pandas DataFrame} of every table, each checked against its sidecar."""
    import pandas as pd

    tables = {}
    for tsv in sorted(Path(folder).rglob("*.tsv")):
        table = pd.read_csv(tsv, sep="\t", dtype=str, na_values=["n/a"], keep_default_na=False)
        columns = {k: v for k, v in json.loads(sidecar_of(tsv).read_text()).items() if isinstance(v, dict)}
        assert list(table.columns) == list(columns), (tsv.name, list(table.columns), list(columns))
        for name, spec in columns.items():
            assert spec.get("Description"), (tsv.name, name)
            values = table[name].dropna()
            if "Levels" in spec:
                assert set(values) <= set(spec["Levels"]), (tsv.name, name, set(values) - set(spec["Levels"]))
            if "Units" in spec:
                pd.to_numeric(values)  # raises on a value that is no number
        tables[str(tsv.relative_to(folder))] = table
    return tables
