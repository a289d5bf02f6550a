// A study as data: its conditions (FrictionStudyCondition: scene, instruction, end, questions),
// the order they are run in per participant (FrictionStudyOrder: \fixed, \latinSquare or
// \random with a seed kept with the session), an introduction, and what counts as covered
// (FrictionStudyCoverage's settings, the area coming from each condition). A study is checked
// when it is made: what is wrong with it is refused with the reason before anyone sees anything.
// run and resume run it with a participant (FrictionStudySession); FrictionStudy.pilot is the
// paper's own (section 4).
FrictionStudy {
	var <name, <conditions, <order, <introduction, <coverage;

	*new { |name, conditions, order = \fixed, introduction = "", coverage|
		^super.newCopyArgs(name, conditions, order, introduction, coverage).prCheck
	}

	// The conditions for the participant numbered participantIndex (0, 1, ...: the Latin square's
	// row), with seed for a random order.
	conditionsFor { |participantIndex = 0, seed = 0|
		^FrictionStudyOrder.of(order, conditions.size, participantIndex, seed).collect { |i| conditions[i] }
	}

	conditionNamed { |conditionName| ^conditions.detect { |c| c.name == conditionName } }

	// A FrictionStudyCoverage for condition.
	coverageFor { |condition|
		var c = coverage;
		^FrictionStudyCoverage(condition.areaMm, c[\slowMmPerS], c[\fastMmPerS], c[\positionBins], c[\speedBins],
			c[\criterion])
	}

	// Runs the study with one participant on server (booted), into folder/participant (a new
	// folder: a code already used is refused). See FrictionStudySession for the arguments.
	run { |participant, folder, server, participantIndex = 0, seed, device, simulated, windows = true,
		participantOut = 0, experimenterOut = 2, deviceIndex = 0|
		^FrictionStudySession(this, participant, folder, server, participantIndex, seed, device, simulated, windows,
			participantOut, experimenterOut, deviceIndex).start
	}

	// Goes on with the session in sessionFolder (one folder made by run) at the condition it was in.
	resume { |sessionFolder, server, device, simulated, windows = true, participantOut = 0, experimenterOut = 2,
		deviceIndex = 0|
		^FrictionStudySession.resume(this, sessionFolder, server, device, simulated, windows, participantOut,
			experimenterOut, deviceIndex)
	}

	// What differs between this study and stored, the study as a session's manifest holds it
	// (parsed JSON): an Array of "where: stored, now" Strings, empty when they agree. Seeds are
	// left out (a procedure's seed may be drawn anew each time it is made; one that changed the
	// levels is found when the stored trials are continued).
	differencesFrom { |stored|
		var compare, found = [];
		compare = { |was, now, where|
			case
				{ was.isKindOf(Dictionary) and: { now.isKindOf(Dictionary) } } {
					(was.keys.asArray ++ now.keys.asArray).asSet.asArray.sort.do { |key|
						if(key != "seed") { compare.(was[key], now[key], where ++ "." ++ key) }
					}
				}
				{ was.isArray and: { now.isArray } and: { was.isString.not } and: { now.isString.not } } {
					max(was.size, now.size).do { |i| compare.(was[i], now[i], where ++ "[" ++ i ++ "]") }
				}
				{ was != now } {
					found = found.add("%: % in the session, % now".format(where.drop(1), was ? "absent",
						now ? "absent"))
				}
		};
		compare.(stored, FrictionStudyFiles.json(this.asEvent).parseJSON, "");
		^found
	}

	asEvent {
		^(name: name, order: order, introduction: introduction, coverage: coverage,
			conditions: conditions.collect(_.asEvent))
	}

	printOn { |stream| stream << this.class.name << "(" << name.cs << ", " << conditions.size << " conditions)" }

	prCheck {
		var where = "FrictionStudy(%)".format(name.cs), defaults;
		if(name.isString.not or: { name.isEmpty }) { Error("FrictionStudy: name must be a non-empty String").throw };
		if(conditions.isSequenceableCollection.not or: { conditions.isEmpty }) {
			Error("%: a study needs at least one condition, got %".format(where, conditions)).throw
		};
		conditions.do { |c|
			if(c.isKindOf(FrictionStudyCondition).not) {
				Error("%: conditions must be FrictionStudyCondition, got %".format(where, c)).throw
			}
		};
		if(conditions.collect(_.name).asSet.size != conditions.size) {
			Error("%: two conditions have one name: %".format(where, conditions.collect(_.name))).throw
		};
		if(FrictionStudyOrder.kinds.includes(order).not) {
			Error("%: order must be one of %, got %".format(where, FrictionStudyOrder.kinds, order.cs)).throw
		};
		if(introduction.isString.not) { Error("%: introduction must be a String".format(where)).throw };
		defaults = (slowMmPerS: 5, fastMmPerS: 300, positionBins: 10, speedBins: 6, criterion: 0.8);
		if(coverage.notNil and: { coverage.isKindOf(Dictionary).not }) {
			Error("%: coverage must be an Event of settings, got %".format(where, coverage)).throw
		};
		(coverage ? ()).keysDo { |key|
			if(defaults.includesKey(key).not) {
				Error("%: unknown coverage setting % (known: %)".format(where, key.cs,
					defaults.keys.asArray.sort.join(", "))).throw
			}
		};
		coverage = defaults.putAll(coverage ? ());
		// Made once here, so that a bad setting is refused now, not at the first condition.
		conditions.do { |c| this.coverageFor(c) };
	}
}
