// FrictionStudySession's folder: the conditions' attempt folders, session.csv, the manifest with
// its provenance, and a resume's reading of them.
+ FrictionStudySession {
	// The folder of attempt (1, 2, ...) of the condition at k in the order.
	prConditionDir { |k, attempt = 1|
		var dir = folder +/+ "%-%".format((k + 1).asString.padLeft(2, "0"), order[k].name);
		^if(attempt > 1) { dir ++ "-attempt" ++ attempt } { dir }
	}

	// The last attempt made at the condition at k (0: none).
	prLastAttempt { |k|
		var n = 0;
		while { File.exists(this.prConditionDir(k, n + 1)) } { n = n + 1 };
		^n
	}

	// session.csv's times count on across a resume (a new sclang's clock starts again): they go on
	// from the last one stored (the wallTime column says how long the session stood).
	prSessionLog { |event, detail|
		this.class.checkEvent(event, true);
		FrictionStudyFiles.appendCsv(folder +/+ "session.csv",
			[(Main.elapsedTime + sessionTimeOffsetS).round(0.001), event, detail, FrictionStudyFiles.now],
			eventsHeader);
	}

	prWriteManifest {
		var dev = device, manifest;
		manifest = (
			study: study.asEvent, participant: participant, participantIndex: participantIndex, seed: seed,
			order: order.collect(_.name), date: FrictionStudyFiles.now, version: this.class.projectVersion,
			sampleRateHz: server.sampleRate, blockSize: server.options.blockSize,
			hardwareBufferSize: server.options.hardwareBufferSize, messageLatencyS: server.latency,
			participantOut: participantOut, experimenterOut: experimenterOut,
			device: if(dev.notNil) {
				(kind: dev.kind, index: dev.index, specs: dev.specs, overrides: dev.overrides,
					source: dev.source.asString, board: dev.boardSetup !? { |b|
						(serial: b[\serial], emulate: b[\emulate], calibration: b[\calibration].asString)
					}, audioDelayS: dev.audioDelay)
			} {
				(kind: \sim, index: deviceIndex, specs: FrictionDevice.paperSpecs, board: nil,
					source: "FrictionHand.explore of the simulated participant, one device per condition",
					audioDelayS: FrictionPilot.paperAudioDelayS)
			},
			simulatedParticipant: simulated !? { simulated.asEvent }, provenance: this.class.provenance
		);
		FrictionStudyFiles.writeText(folder +/+ "manifest.json", FrictionStudyFiles.json(manifest) ++ "\n");
	}

	// What made the data, for a manifest: the project's commit (build-info.scd, written by cmake
	// --install) and whether its tree had changes, SuperCollider's version, the platform, the
	// python3 the report runs (its version) and the local time zone (UTC offset); "unknown" where
	// one cannot be found.
	*provenance {
		var info = KineticFriction.extensionDir +/+ "build-info.scd", build, python, zone;
		build = if(File.exists(info)) { File.readAllString(info).interpret } ? ();
		python = (FrictionStudy.defaultPython.shellQuote ++ " --version 2>&1").unixCmdGetStdOut;
		python = python.replace("Python", "").stripWhiteSpace;
		zone = if(thisProcess.platform.name != \windows) { "date +%z".unixCmdGetStdOut.stripWhiteSpace } { "" };
		^(project: this.projectVersion, commit: build[\commit] ? "unknown",
			uncommittedChanges: build[\dirty] ? "unknown", supercollider: Main.version,
			platform: thisProcess.platform.name,
			python: if(python.isEmpty) { "unknown" } { python }, timeZone: if(zone.isEmpty) { "unknown" } { zone })
	}

	// The project's version (the extension folder's quark file), or "unknown".
	*projectVersion {
		var path = KineticFriction.extensionDir +/+ "KineticFriction.quark";
		^if(File.exists(path)) { File.readAllString(path).interpret[\version] } { "unknown" }
	}

	prResume { |manifest|
		var names = manifest["order"];
		if(names.size != order.size or: { names.any { |n| study.conditionNamed(n.asSymbol).isNil } }) {
			Error("FrictionStudySession.resume: the session's conditions % are not the study's %".format(
				names, study.conditions.collect(_.name))).throw
		};
		order = names.collect { |n| study.conditionNamed(n.asSymbol) };
		// The first condition without its end: the one the session was in.
		position = order.size;
		order.do { |c, k|
			var events = this.prConditionDir(k, this.prLastAttempt(k)) +/+ "events.csv";
			if(position == order.size and: {
				File.exists(events).not or: { File.readAllString(events).contains("\"end\"").not }
			}) { position = k }
		};
		FrictionStudyFiles.readCsv(folder +/+ "session.csv").last !? { |last|
			sessionTimeOffsetS = max(0, last[\timeS].asFloat - Main.elapsedTime)
		};
		this.prCheckStimuli;
		this.prSessionLog(\resume, "at % of %".format(position + 1, order.size));
		this.prPlay;
	}
}
