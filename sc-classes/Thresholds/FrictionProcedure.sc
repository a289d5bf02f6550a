// What a threshold procedure is to FrictionThreshold, a study session and FrictionObserver: the
// level of the next trial (nil when it is finished), the answer to a level, the trials given
// (Events of level and correct), its estimate and the levels it can ask for. FrictionStaircase,
// FrictionQuestPlus and FrictionConstantStimuli are the ready-made ones; a procedure of one's own
// subclasses this.
FrictionProcedure {
	// The level of the next trial, or nil once finished.
	next { ^this.subclassResponsibility(thisMethod) }
	// The answer (correct: true or false) to a trial at level.
	respond { |level, correct| ^this.subclassResponsibility(thisMethod) }
	isFinished { ^this.subclassResponsibility(thisMethod) }
	// The trials given so far: Events of level and correct, in order.
	trials { ^this.subclassResponsibility(thisMethod) }
	// An Event with at least threshold (nil before any trial).
	estimate { ^this.subclassResponsibility(thisMethod) }
	// The lowest and highest level it can ask for (inf: unbounded); checked against a device's
	// force range before a run (FrictionThreshold.checkRange).
	levelRange { ^[0, inf] }
	// Its settings as an Event (kind: first), for the session's files.
	asEvent { ^(kind: this.class.name) }
}
