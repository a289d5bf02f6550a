// What of a condition has been explored: a map of the fragment on the surface (positionBins
// parts of areaMm) against the speed range (speedBins parts of [slowMmPerS, fastMmPerS], on a log
// scale: the paper's "from quite slow to fast"). A cell is covered once the puck has been seen in
// it; the criterion is met when the fraction covered reaches criterion. The report
// (python/kfharness/study_report.py) computes the same map from the device recording.
FrictionStudyCoverage {
	var <areaMm, <slowMmPerS, <fastMmPerS, <positionBins, <speedBins, <criterion;
	var <cells, <count = 0;

	*new { |areaMm, slowMmPerS = 5, fastMmPerS = 300, positionBins = 10, speedBins = 6, criterion = 0.8|
		^super.newCopyArgs(areaMm, slowMmPerS, fastMmPerS, positionBins, speedBins, criterion).prInit
	}

	// The cell (positionIndex, speedIndex) of a position (mm) and speed (mm/s), or nil outside.
	cellOf { |positionMm, speedMmPerS|
		var p, v, speed = speedMmPerS.abs;
		if(positionMm < areaMm[0] or: { positionMm >= areaMm[1] }) { ^nil };
		if(speed < slowMmPerS or: { speed >= fastMmPerS }) { ^nil };
		p = ((positionMm - areaMm[0]) / (areaMm[1] - areaMm[0]) * positionBins).floor.asInteger;
		v = ((speed / slowMmPerS).log / (fastMmPerS / slowMmPerS).log * speedBins).floor.asInteger;
		^[p.clip(0, positionBins - 1), v.clip(0, speedBins - 1)]
	}

	// Notes the puck at positionMm moving at speedMmPerS; true when this covered a new cell.
	add { |positionMm, speedMmPerS|
		var cell = this.cellOf(positionMm, speedMmPerS);
		if(cell.isNil or: { cells[cell[0]][cell[1]] }) { ^false };
		cells[cell[0]][cell[1]] = true;
		count = count + 1;
		^true
	}

	fraction { ^count / (positionBins * speedBins) }
	isMet { ^this.fraction >= criterion }
	// The fraction of the area's parts and of the speed range's parts visited at all.
	areaFraction { ^cells.count { |row| row.includes(true) } / positionBins }
	speedFraction { ^(0 .. speedBins - 1).count { |v| cells.any { |row| row[v] } } / speedBins }

	reset { cells = Array.fill(positionBins, { Array.fill(speedBins, false) }); count = 0 }

	asEvent {
		^(areaMm: areaMm, slowMmPerS: slowMmPerS, fastMmPerS: fastMmPerS, positionBins: positionBins,
			speedBins: speedBins, criterion: criterion)
	}

	prInit {
		var where = "FrictionStudyCoverage";
		if(areaMm.isSequenceableCollection.not or: { areaMm.size != 2 } or: { areaMm[0] >= areaMm[1] }) {
			Error("%: areaMm must be [fromMm, toMm] with fromMm < toMm, got %".format(where, areaMm)).throw
		};
		if(slowMmPerS.isNumber.not or: { slowMmPerS <= 0 } or: { fastMmPerS.isNumber.not }
			or: { fastMmPerS <= slowMmPerS }) {
			Error("%: speeds must be 0 < slowMmPerS < fastMmPerS, got % and %".format(where, slowMmPerS, fastMmPerS)).throw
		};
		[\positionBins, positionBins, \speedBins, speedBins].pairsDo { |name, n|
			if(n.isInteger.not or: { n < 1 } or: { n > 100 }) {
				Error("%: % must be an Integer from 1 to 100, got %".format(where, name, n)).throw
			}
		};
		if(criterion.isNumber.not or: { criterion <= 0 } or: { criterion > 1 }) {
			Error("%: criterion must be a fraction in (0, 1], got %".format(where, criterion)).throw
		};
		this.reset;
	}
}
