"""The report's statistics stage, on the tidy tables (report_tables): where each mapping's friction
is raised, and the "binds" statistic, the paper's observation that raised friction binds movement:
the speed where the friction is raised with friction off minus on, per participant and mapping,
and a paired t test over participants per mapping."""
import numpy as np
import pandas as pd

# "Where the friction is": a part of the fragment BIND_BIN_MM wide is raised when the mean force
# commanded there, over every friction-on condition of its mapping (all participants), lies above
# the middle between the device's minimum force and the highest force those conditions commanded
# (their 99th percentile). 0.5 mm resolves mapping 3's force bumps (two per 12.5 mm cycle); a
# part needs BIND_MIN_REPORTS reports of friction on to be judged.
BIND_BIN_MM = 0.5
BIND_MIN_REPORTS = 5
PART_COLUMNS = ["mapping", "part", "from_mm", "to_mm", "mean_force_n", "raised"]
PAIR_COLUMNS = ["participant", "mapping", "speed_off", "speed_on", "difference"]
TEST_COLUMNS = ["mapping", "raised_mm", "area_mm", "n", "mean_off", "mean_on", "mean_difference", "sd_difference", "t",
                "df", "p"]


def _edges(area):
    return np.arange(area[0], area[1] + BIND_BIN_MM / 2, BIND_BIN_MM)


def part_of(x_mm, edges):
    """The part (from 0) each position lies in; -1 or len(edges) - 1 outside the fragment."""
    return np.digitize(x_mm, edges) - 1


def raised_parts(samples, areas, min_force_n):
    """A row per part of each mapping's fragment (PART_COLUMNS): the mean force commanded there with
    friction on (nan with fewer than BIND_MIN_REPORTS reports) and whether it is raised. `areas`:
    {mapping: (from_mm, to_mm)}."""
    tables = []
    on = samples[samples.friction.astype(bool) & np.isfinite(samples.force_n.astype(float))]
    for mapping, group in on.groupby("mapping", sort=True):
        edges = _edges(areas[mapping])
        parts = len(edges) - 1
        part = part_of(group.x_mm.to_numpy(float), edges)
        seen = group.force_n[(part >= 0) & (part < parts)].astype(float)
        by_part = seen.groupby(part[(part >= 0) & (part < parts)]).agg(["count", "mean"]).reindex(range(parts))
        mean = by_part["mean"].where(by_part["count"] >= BIND_MIN_REPORTS).to_numpy(float)
        top = np.percentile(seen, 99) if len(seen) else np.nan
        with np.errstate(invalid="ignore"):
            raised = mean > (min_force_n + top) / 2
        tables.append(pd.DataFrame(dict(mapping=mapping, part=range(parts), from_mm=edges[:-1], to_mm=edges[1:],
                                        mean_force_n=mean, raised=raised), columns=PART_COLUMNS))
    return pd.concat(tables, ignore_index=True) if tables else pd.DataFrame(columns=PART_COLUMNS)


def where_raised(samples, parts):
    """True for each sample that lies in a raised part of its mapping (False where its mapping has
    no parts)."""
    raised = np.zeros(len(samples), dtype=bool)
    for mapping, rows in parts.groupby("mapping"):
        mine = (samples.mapping == mapping).to_numpy()
        flags = rows.sort_values("part").raised.to_numpy(bool)
        edges = np.append(rows.from_mm.to_numpy(float), rows.to_mm.max())
        part = part_of(samples.x_mm[mine].to_numpy(float), edges)
        inside = (part >= 0) & (part < len(flags))
        hit = np.zeros(len(part), dtype=bool)
        hit[inside] = flags[part[inside]]
        raised[mine] = hit
    return raised


def binds(samples, parts):
    """Per mapping: the typical speed where the friction is raised with friction off minus on, per
    participant (the median of its |speed| there: the speed it moved at most of the time, which the
    few fast passes after a release do not pull up), and the paired t test over participants
    (scipy.stats.ttest_rel, two-sided). Returns (the test per mapping (TEST_COLUMNS), the pairs
    per participant and mapping (PAIR_COLUMNS))."""
    from scipy import stats
    there = samples[where_raised(samples, parts)]
    medians = there.v_mm_s.astype(float).abs().groupby([there.participant, there.mapping,
                                                        there.friction.astype(bool)]).median()
    if not len(medians):
        return pd.DataFrame(columns=TEST_COLUMNS), pd.DataFrame(columns=PAIR_COLUMNS)
    pairs = medians.unstack("friction").reindex(columns=[False, True]).dropna().reset_index()
    pairs = pd.DataFrame(dict(participant=pairs.participant, mapping=pairs.mapping, speed_off=pairs[False],
                              speed_on=pairs[True], difference=pairs[False] - pairs[True]), columns=PAIR_COLUMNS)
    rows = []
    for mapping, pair in pairs.groupby("mapping", sort=True):
        off, on, diff = pair.speed_off.to_numpy(float), pair.speed_on.to_numpy(float), pair.difference.to_numpy(float)
        n = len(off)
        t, p = float("nan"), float("nan")
        if n >= 2 and np.std(diff) > 0:
            test = stats.ttest_rel(off, on)
            t, p = float(test.statistic), float(test.pvalue)
        mine = parts[parts.mapping == mapping]
        rows.append(dict(mapping=mapping, raised_mm=float(mine.raised.sum() * BIND_BIN_MM),
                         area_mm=float(mine.to_mm.max() - mine.from_mm.min()), n=n, mean_off=float(np.mean(off)),
                         mean_on=float(np.mean(on)), mean_difference=float(np.mean(diff)),
                         sd_difference=float(np.std(diff, ddof=1)) if n > 1 else float("nan"), t=t, df=n - 1, p=p))
    return pd.DataFrame(rows, columns=TEST_COLUMNS), pairs
