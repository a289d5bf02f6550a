"""Simulated runs of the threshold procedures (sclang: FrictionConstantStimuli, FrictionStaircase,
FrictionQuestPlus) against a model observer (FrictionObserver), all in one headless sclang with no
server, for the bench (bench/kfbench/thresholds.py) and the tests
(tests/scenes/test_threshold_procedures.py). Each run has its own seeds (observer and procedure),
derived from the run's index, so every run is reproducible on its own.

A run's record: the procedure's name, the run's index, its estimate (an Event as a dict) after each
checkpoint's number of trials, and every trial's level and answer."""
import json

from . import sclang

# The observer of the bench and the tests, in the stimulus' own unit: a threshold of 1 (the
# Weibull's, 81.6 % correct at lapse 0), slope 3.5 (psignifit's and QUEST's customary middle),
# lapse 0.02 (a point of QUEST+'s lapse grid), guess 1/2.
OBSERVER = dict(threshold=1.0, slope=3.5, lapse=0.02, guess=0.5)
# QUEST+'s levels and the constant stimuli's: 30 from 0.1 to 10 times the threshold (log-spaced),
# and 7 spanning 55 % to 99 % correct.
QUEST_LEVELS = "FrictionPsychometric.logLevels(0.1, 10, 30)"
CONSTANT_LEVELS = "[0.45, 0.6, 0.75, 0.9, 1.1, 1.35, 1.7]"

# name: (sclang making the procedure from `seed`, the checkpoints: numbers of trials).
PROCEDURES = {
    # One grid for all runs: its p(correct) per level is worked out once.
    "constant": (f"FrictionConstantStimuli({CONSTANT_LEVELS}, 40, seed, ~kfGrid ?? {{ ~kfGrid = "
                 f"FrictionConstantStimuli.defaultGrid({CONSTANT_LEVELS}) }})", [70, 140, 280]),
    "staircase 1-up-2-down": ("FrictionStaircase(2, 2, [0.2, 0.1, 0.05], \\log, 1000, 80)", [20, 40, 80]),
    "staircase 1-up-3-down": ("FrictionStaircase(2, 3, [0.2, 0.1, 0.05], \\log, 1000, 80)", [20, 40, 80]),
    "questplus": (f"FrictionQuestPlus({QUEST_LEVELS}, maxTrials: 48)", [12, 24, 48]),
}

SCRIPT = r"""
var observer = %(observer)s, procedures = %(procedures)s, file = File(%(out)s, "w");
var eventJson = { |e| "{" ++ e.keys.asArray.sort.collect { |k|
	var v = e[k]; "\"%%\": %%".format(k, if(v.isNumber) { if(v.isNaN or: { v.abs == inf }) { "null" } { v } } {
		if(v.isNil) { "null" } { v.asString.asCompileString } })
}.join(", ") ++ "}" };
procedures.pairsDo { |name, spec|
	spec[2].do { |run|
		var seed = %(seed)d + (run * 7919), estimates = (), procedure = spec[0].value(seed + 1);
		observer.value(seed).runProcedure(procedure, { |p, n|
			if(spec[1].includes(n)) { estimates[n] = p.estimate }
		});
		file.write("{\"procedure\": %%, \"run\": %%, \"estimates\": {%%}, \"levels\": %%, \"correct\": %%}\n".format(
			name.asString.asCompileString, run,
			spec[1].select { |n| estimates[n].notNil }.collect { |n|
				"\"%%\": %%".format(n, eventJson.(estimates[n])) }.join(", "),
			procedure.trials.collect(_.level).asCompileString,
			procedure.trials.collect { |t| if(t.correct) { 1 } { 0 } }.asCompileString))
	}
};
file.close;
"""


def _observer_code(observer):
    return ("{ |seed| FrictionObserver(%(threshold)r, %(slope)r, %(lapse)r, %(guess)r, seed) }" % observer)


def simulate(runs, work_path, seed=1000, observer=OBSERVER, timeout=1800, include_paths=None):
    """Runs each procedure named in `runs` (name: number of runs) against the observer, in one
    sclang; returns the runs' records."""
    procedures = "[" + ", ".join(
        f"{sclang.sc_string(name)}, [{{ |seed| {PROCEDURES[name][0]} }}, {PROCEDURES[name][1]}, {count}]"
        for name, count in runs.items()) + "]"
    code = SCRIPT % dict(observer=_observer_code(observer), procedures=procedures, out=sclang.sc_string(work_path),
                         seed=seed)
    sclang.run_script(code, timeout=timeout, name="thresholds", include_paths=include_paths)
    return [json.loads(line) for line in open(work_path)]
