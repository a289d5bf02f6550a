// What of a condition has been explored: a map of the fragment on the surface (positionBins
// parts of areaMm) against the speed range (speedBins parts of [slowMmPerS, fastMmPerS], on a log
// scale: the paper's "from quite slow to fast"). A cell is covered once the puck has been seen in
// it, or has passed through it between two positions seen in a row (samples 8 ms apart skip
// parts of 0.6 mm at mapping 1's speeds otherwise); the criterion is met when the fraction covered
// reaches criterion. A session adds the samples of its device recording (FrictionStudyTrack); the
// report (python/kfstudy/session_folder.py, coverage) computes the same map from the same file.
FrictionStudyCoverage {
	var <areaMm, <slowMmPerS, <fastMmPerS, <positionBins, <speedBins, <criterion;
	var <cells, <count = 0;

	*new { |areaMm, slowMmPerS = 5, fastMmPerS = 300, positionBins = 10, speedBins = 6, criterion = 0.8|
		^super.newCopyArgs(areaMm, slowMmPerS, fastMmPerS, positionBins, speedBins, criterion).prInit
	}

	// The speed's row (from 0, slow), or nil outside the speed range.
	speedIndexOf { |speedMmPerS|
		var speed = speedMmPerS.abs;
		if(speed < slowMmPerS or: { speed >= fastMmPerS }) { ^nil };
		^((speed / slowMmPerS).log / (fastMmPerS / slowMmPerS).log * speedBins).floor.asInteger.clip(0, speedBins - 1)
	}

	// The position's column (from 0), or nil outside the area.
	positionIndexOf { |positionMm|
		if(positionMm < areaMm[0] or: { positionMm >= areaMm[1] }) { ^nil };
		^((positionMm - areaMm[0]) / (areaMm[1] - areaMm[0]) * positionBins).floor.asInteger.clip(0, positionBins - 1)
	}

	// The cell [positionIndex, speedIndex] of a position (mm) and speed (mm/s), or nil outside.
	cellOf { |positionMm, speedMmPerS|
		var p = this.positionIndexOf(positionMm), v = this.speedIndexOf(speedMmPerS);
		^if(p.isNil or: { v.isNil }) { nil } { [p, v] }
	}

	// Notes the puck moving at speedMmPerS from fromMm to toMm (the positions of two frames in a
	// row): every column between them is covered at that speed. The number of new cells.
	add { |fromMm, toMm, speedMmPerS|
		var v = this.speedIndexOf(speedMmPerS), lo, hi, added = 0;
		if(v.isNil or: { max(fromMm, toMm) < areaMm[0] } or: { min(fromMm, toMm) >= areaMm[1] }) { ^0 };
		lo = this.prColumn(min(fromMm, toMm));
		hi = this.prColumn(max(fromMm, toMm));
		(lo .. hi).do { |p|
			if(cells[p][v].not) { cells[p][v] = true; count = count + 1; added = added + 1 }
		};
		^added
	}

	fraction { ^count / (positionBins * speedBins) }
	isMet { ^this.fraction >= criterion }
	// The fraction of the area's parts and of the speed range's parts visited at all.
	areaFraction { ^cells.count { |row| row.includes(true) } / positionBins }
	speedFraction { ^(0 .. speedBins - 1).count { |v| cells.any { |row| row[v] } } / speedBins }

	// The cells as text: a row of positionBins 0s and 1s (1: covered) per speed part, slowest first,
	// joined by "/" (the session's coverageMap event; kfstudy.session_folder reads it).
	mapString { ^(0 .. speedBins - 1).collect { |v| cells.collect { |row| if(row[v]) { $1 } { $0 } }.join }.join("/") }

	reset { cells = Array.fill(positionBins, { Array.fill(speedBins, false) }); count = 0 }

	// The column of a position, clipped into the area.
	prColumn { |positionMm|
		if(positionMm < areaMm[0]) { ^0 };
		if(positionMm >= areaMm[1]) { ^positionBins - 1 };
		^this.positionIndexOf(positionMm)
	}

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
			Error("%: speeds must be 0 < slowMmPerS < fastMmPerS, got % and %".format(where, slowMmPerS,
				fastMmPerS)).throw
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
