// The puck's track in a condition as its device recording has it, read while the server writes it:
// positions summed from the reports' counts, on the mouse's own clock, and the speed over
// speedReports reports at the middle of their ends, as the report computes them
// (python/kfstudy/session_folder.py, Condition.track). The coverage map made from it is the one the
// report makes from the recording whatever the machine does to the device thread: a map of the
// trajectory as the server rendered it saw the puck stop and jump where the kernel held that
// thread back (fresh clone 100: reports taken 30 to 37 ms late, and a map 10 cells from the
// recording's).
//
// The server writes whole lines every 10 ms (docs/record-format.md); a line still being written
// is read at the next read. The file must be on this machine, as the session's folder is.
FrictionStudyTrack {
	// Speeds are differences over this many reports (40 ms at 125 Hz): session_folder.SPEED_REPORTS.
	classvar <speedReports = 5;
	var <path, <recordedAtS, <samples, offset = 0, countMm, firstDeviceS, counts = 0, recent, coveredUpTo = 0,
	lastCoveredMm;

	// path: the recording (device.kfsession); recordedAtS: the condition's time (s) its first report
	// is placed at (the recordDevice event's).
	*new { |path, recordedAtS| ^super.newCopyArgs(path, recordedAtS).prInit }

	prInit { samples = []; recent = [] }

	// Reads the lines written since the last read; the samples [timeS, positionMm, speedMmPerS]
	// they add are appended to samples.
	read {
		var file, length, text, end;
		if(File.exists(path).not) { ^this };
		file = File(path, "r");
		if(file.isOpen.not) { ^this };
		{
			length = file.length;
			if(length > offset) {
				file.seek(offset, 0);
				text = String.newClear(length - offset);
				file.read(text);
			}
		}.protect { file.close };
		end = text !? { text.findBackwards("\n") };
		if(end.isNil) { ^this };
		offset = offset + end + 1;
		text.copyRange(0, end - 1).split($\n).do { |line| this.prLine(line) };
	}

	// Adds to coverage the samples read since the last call that lie from fromS on (the condition's
	// start), each moving from the one before it (FrictionStudyCoverage.add).
	coverNew { |coverage, fromS|
		(coveredUpTo .. samples.size - 1).do { |i| this.prCover(coverage, samples[i], fromS, inf) };
		coveredUpTo = samples.size;
	}

	// coverage made again from every sample from fromS to toS (the condition's start and end), as
	// the report does.
	coverAll { |coverage, fromS, toS|
		coverage.reset;
		lastCoveredMm = nil;
		samples.do { |sample| this.prCover(coverage, sample, fromS, toS) };
		coveredUpTo = samples.size;
	}

	prCover { |coverage, sample, fromS, toS|
		if(sample[0] >= fromS and: { sample[0] <= toS }) {
			coverage.add(lastCoveredMm ? sample[1], sample[1], sample[2]);
			lastCoveredMm = sample[1];
		}
	}

	prLine { |line|
		var fields, deviceS, first, dt;
		if(countMm.isNil) {
			// The header: kf-session 1 countMm=... (only the mm of a count along x is needed).
			line.split($ ).do { |field| if(field.beginsWith("countMm=")) { countMm = field.drop(8).asFloat } };
			if(countMm.isNil) { Error("FrictionStudyTrack: % has no countMm in its header".format(path)).throw };
			^this
		};
		if(line.isEmpty or: { line[0] != $R }) { ^this };
		fields = line.split($ );
		deviceS = fields[2].asFloat;
		firstDeviceS = firstDeviceS ? deviceS;
		counts = counts + fields[3].asInteger;
		recent = recent.add([deviceS - firstDeviceS + recordedAtS, counts * countMm]).keep(speedReports.neg - 1);
		if(recent.size <= speedReports) { ^this };
		first = recent[0];
		dt = recent.last[0] - first[0];
		if(dt > 0) {
			samples = samples.add([(first[0] + recent.last[0]) / 2, (first[1] + recent.last[1]) / 2,
				(recent.last[1] - first[1]) / dt]);
		}
	}
}
