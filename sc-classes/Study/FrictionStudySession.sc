// One participant's session of a FrictionStudy, run on a server: the session folder and the run.
//
// The folder (folder/participant): manifest.json (study, participant, order, seed, date, the
// project's version and provenance, the device with its settings, board and calibration, sample
// rate and the latencies in use), session.csv (start, resume, finish, abort), answers.csv (one line per answer,
// written and flushed as it is given), and per condition a folder NN-name (NN its place in the
// order) with device.kfsession (the device recording), audio.wav (the participant's audio as
// heard) and events.csv (prepare, start, pause, resume, done, end... with times in s from its
// prepare line). A condition cut short (a crash, a kill, repeat) keeps its folder as it was and
// runs again into NN-name-attemptK (K = 2, 3, ...): the last attempt is the condition's.
//
// Everything is checked before the first participant sees anything (the study, the code, the
// folder, the server, the channels, the device): a refusal is an Error with the reason.
//
// This file: the session's state, its control and the run of its conditions (exploration and
// questions, the audio recording). Its other roles, each in a file of its own: the threshold
// conditions (extFrictionStudySessionThreshold.sc), the watch of the server, the device and sclang
// (extFrictionStudySessionWatch.sc), the folder, manifest and resume (extFrictionStudySessionFolder.sc).
FrictionStudySession {
	classvar <answersHeader, <eventsHeader, <trialsHeader, <conditionEvents, <sessionEvents;
	// A server that has not answered a /sync for this long (s) is lost: the session fails.
	classvar <>lostAfterS = 3;
	// The client watch of the devices a session plays on (FrictionDevice.watchClient): a server
	// that has not heard this sclang for this long (s) turns the force off. 0: no watch.
	classvar <>clientTimeoutS = 2;
	var <study, <participant, <folder, <server, <participantIndex, <seed, <device, <simulated, <windows;
	var <participantOut, <experimenterOut, <deviceIndex;
	var <order, <position = 0, <state = \ready, <condition, <conditionDevice, <pilot, <coverage, <track, <monitor;
	var <conditionDir, <attempt = 0, <question, <endedBy, <paused = false, <stats;
	var <participantWindow, <experimenterWindow, <>onEnd;
	var ending, answerValue, listenSynth, recorder, preparedT0, conditionT0, pausedS = 0, pauseT0;
	var buttonsSynth, buttonsResponder, startedAtS;
	var routine, lastAnswerT, watchTickT, watchId, experiment, sessionTimeOffsetS = 0, deviceTimeoutBefore;

	*initClass {
		answersHeader = #[participant, position, condition, attempt, question, kind, answer, source, timeS, wallTime];
		eventsHeader = #[timeS, event, detail, wallTime];
		// What events.csv and session.csv may hold (log refuses anything else: a misspelt event
		// would be lost on the report): the same names as kfstudy.session_folder's.
		conditionEvents = #[prepare, recordDevice, recordAudio, experiment, observer, continue, start, pause, resume,
			trial, done, maxTime, repeat, abort, lost, coverage, coverageMap, estimate, answer, end];
		sessionEvents = #[start, resume, finish, abort, error];
		trialsHeader = #[participant, position, condition, attempt, trial, level, target, answer, correct, startS,
			interval1S, interval2S, answerS, wallTime];
	}

	// study: a FrictionStudy. participant: a code (letters, digits, _ and -), never used before in
	// root (the folder the sessions go into). server: booted, with outputs for both pairs.
	// participantIndex: the participant's number (the Latin square's row). seed: of a random order
	// (nil: drawn, and kept in the manifest). device: an open FrictionDevice, or simulated: a
	// FrictionStudySimParticipant (a simulated device opened per condition in deviceIndex).
	// windows: show the participant's and the experimenter's windows. participantOut and
	// experimenterOut: the first channels of the two output pairs.
	*new { |study, participant, root, server, participantIndex = 0, seed, device, simulated, windows = true,
		participantOut = 0, experimenterOut = 2, deviceIndex = 0|
		^super.new.prInit(study, participant, root, server, participantIndex, seed, device, simulated, windows,
			participantOut, experimenterOut, deviceIndex, false)
	}

	// The session in sessionFolder (made by FrictionStudy.run) again, from the condition it was in;
	// study must be the one it was started with (its name and conditions are compared).
	*resume { |study, sessionFolder, server, device, simulated, windows = true, participantOut = 0,
		experimenterOut = 2, deviceIndex = 0|
		var manifest, path = sessionFolder.asString.standardizePath +/+ "manifest.json";
		if(File.exists(path).not) {
			Error("FrictionStudySession.resume: no session in % (no manifest.json)".format(sessionFolder)).throw
		};
		manifest = File.readAllString(path).parseJSON;
		if(study.isKindOf(FrictionStudy).not or: { manifest["study"]["name"] != study.name }) {
			Error("FrictionStudySession.resume: the session in % is of the study %, not %".format(
				sessionFolder, manifest["study"]["name"].cs, study !? { study.name.cs })).throw
		};
		// Its data would mix two studies: refused, with what differs.
		study.differencesFrom(manifest["study"]) !? { |found|
			if(found.notEmpty) {
				Error("FrictionStudySession.resume: the study % is not the one the session in % was started with:\n%"
					.format(study.name.cs, sessionFolder, found.collect("\t" ++ _).join("\n"))).throw
			}
		};
		^super.new.prInit(study, manifest["participant"], sessionFolder.asString.standardizePath.dirname, server,
			manifest["participantIndex"].asInteger, manifest["seed"].asInteger, device, simulated, windows,
			participantOut, experimenterOut, deviceIndex, true).prResume(manifest)
	}

	// ---- control: from the windows, keys, or code ----

	// The participant (or by: \window, \key, \button (a puck button), \code) is done exploring.
	// During the introduction, it ends the introduction.
	done { |by = \participant|
		if((state == \running and: { paused.not }) or: { state == \introduction }) { endedBy = by; ending = \done }
	}
	// The experimenter ends the condition (its questions follow).
	next { this.done(\experimenter) }
	// The condition runs again from its start (what it wrote is kept as an attempt).
	repeat { if(state == \running) { ending = \repeat } }
	abort { if(state == \running or: { state == \questions } or: { state == \introduction }) { ending = \abort } }
	// Pauses (the pilot stops: the magnet at rest, nothing heard) or goes on.
	pause { |on = true|
		if(state != \running or: { on == paused }) { ^this };
		paused = on;
		if(on) { pauseT0 = Main.elapsedTime; pilot.free; this.log(\pause) } {
			pausedS = pausedS + (Main.elapsedTime - pauseT0);
			pilot.play;
			this.log(\resume)
		};
	}
	// The answer to the question asked now (checked by it; an Error if it does not fit).
	answer { |value, source = \participant|
		if(state != \questions or: { question.isNil }) {
			Error("FrictionStudySession: no question is asked now").throw
		};
		answerValue = [question.check(value), source];
	}

	// ---- what it is at ----

	isOver { ^[\finished, \aborted, \failed].includes(state) }
	conditionCount { ^order.size }
	// Time in the condition (s), pauses left out.
	elapsedS {
		if(conditionT0.isNil) { ^0 };
		^Main.elapsedTime - conditionT0 - pausedS - if(paused) { Main.elapsedTime - pauseT0 } { 0 }
	}

	// Starts the session (a new one; resume starts itself).
	start {
		if(state != \ready) { ^this };
		this.prCheckStimuli;
		this.prWriteManifest;
		this.prSessionLog(\start, "");
		this.prPlay;
	}

	// event, if it is one of conditionEvents (inSession: sessionEvents); else an Error.
	*checkEvent { |event, inSession = false|
		var names = if(inSession) { sessionEvents } { conditionEvents };
		if(names.includes(event).not) {
			Error("FrictionStudySession: % is not a % event (%)".format(event.cs,
				if(inSession) { "session" } { "condition" }, names.join(", "))).throw
		};
		^event
	}

	// A line in the condition's events.csv, with the time since its prepare line; returns that
	// time (s) as the file has it.
	log { |event, detail = ""|
		var timeS = this.prLogTime.asString;
		this.class.checkEvent(event);
		conditionDir !? {
			FrictionStudyFiles.appendCsv(conditionDir +/+ "events.csv",
				[timeS, event, detail, FrictionStudyFiles.now], eventsHeader)
		};
		^timeS.asFloat
	}

	prLogTime { ^(Main.elapsedTime - (preparedT0 ? Main.elapsedTime)).round(0.001) }

	printOn { |stream| stream << this.class.name << "(" << participant.cs << ", " << state << ")" }

	// ---- the run ----

	prPlay {
		deviceTimeoutBefore = device !? _.clientTimeoutS;
		routine = Routine {
			var result;
			try {
				SynthDef(\frictionStudyListen, { Out.ar(\out.kr(2), In.ar(\in.kr(0), 2)) }).add;
				// A press of any of the puck's buttons (FrictionButtons) is the participant's "done".
				SynthDef(\frictionStudyButtons, {
					SendReply.kr(FrictionButtons.kr(\device.kr(0)).sum > 0, '/kfStudyButton', 1)
				}).add;
				this.prSync;
				this.prWatch;
				if(windows) {
					participantWindow = FrictionStudyParticipantWindow(this);
					experimenterWindow = FrictionStudyExperimenterWindow(this);
				};
				if(position == 0 and: { simulated.isNil } and: { windows }) { this.prIntroduction };
				while { position < order.size and: { this.isOver.not } } {
					condition = order[position];
					result = this.prRunCondition;
					switch(result,
						\end, { position = position + 1 },
						\abort, { state = \aborted; this.prSessionLog(\abort, condition.name) }
					);
				};
				if(this.isOver.not) { state = \finished; this.prSessionLog(\finish, "") };
			} { |error|
				state = \failed;
				this.prSessionLog(\error, error.errorString);
				error.reportError;
				this.prFreeAfterFailure;
			};
			this.prReleaseDevice;
			participantWindow !? { participantWindow.showEnd };
			experimenterWindow !? { experimenterWindow.refresh };
			onEnd.value(this);
		}.play(AppClock);
	}

	prIntroduction {
		state = \introduction;
		ending = nil;
		participantWindow.showInstruction(study.introduction, "I am ready to begin");
		while { ending.isNil } { 0.05.wait };
		if(ending == \abort) { state = \aborted; this.prSessionLog(\abort, "introduction") };
	}

	prRunCondition {
		var s = condition.settings, stoppedAtS;
		preparedT0 = Main.elapsedTime;
		conditionT0 = nil;
		pausedS = 0;
		paused = false;
		attempt = this.prLastAttempt(position) + 1;
		conditionDir = this.prConditionDir(position, attempt);
		File.mkdir(conditionDir);
		this.log(\prepare, condition.name);
		state = \preparing;
		// A simulated participant's hand waits until the condition starts (prStartRunning): the
		// set-up before it takes 0.06 to 1.5 s, the more the busier the machine.
		conditionDevice = if(simulated.notNil) {
			FrictionDevice.sim(server, deviceIndex, simulated.handFor(condition), (handHeld: true), replace: true)
		} { device };
		conditionDevice.record(conditionDir +/+ "device.kfsession");
		track = FrictionStudyTrack(conditionDir +/+ "device.kfsession", this.log(\recordDevice));
		if(clientTimeoutS > 0) { conditionDevice.watchClient(clientTimeoutS) };
		if(condition.isThreshold) { ^this.prRunThreshold };
		pilot = FrictionPilot(conditionDevice, s[\mapping], s[\friction], s[\origin], if(s[\audio]) { s[\amp] } { 0 },
			participantOut);
		pilot.play;
		this.prSync;
		listenSynth = Synth.after(pilot.synth, \frictionStudyListen, [\in, participantOut, \out, experimenterOut]);
		buttonsSynth = Synth.tail(server, \frictionStudyButtons, [\device, conditionDevice.index]);
		buttonsResponder = OSCFunc({ this.done(\button) }, '/kfStudyButton', server.addr,
			argTemplate: [buttonsSynth.nodeID]);
		this.prRecordAudio;
		stats = (speedSum: 0, speedCount: 0, maxForceN: 0, friction: s[\friction], audio: s[\audio]);
		monitor = FrictionViewMonitor.pilot(pilot, 50, 6, { |m| this.prFrame(m) });
		participantWindow !? { participantWindow.showInstruction(condition.instruction) };
		experimenterWindow !? { experimenterWindow.showCondition };
		this.prStartRunning;
		while { ending.isNil } {
			0.05.wait;
			track.read.coverNew(coverage, startedAtS);
			if(paused.not) {
				if(simulated.notNil and: { simulated.isDone(coverage, this.elapsedS, condition) }) {
					this.done(\participant)
				};
				if(ending.isNil and: { this.elapsedS >= condition.maxTimeS }) { ending = \maxTime; endedBy = \time };
			};
		};
		state = \stopping;
		stoppedAtS = this.log(ending, endedBy ? "");
		// The map logged is the recording's from the start to this line (the report's end of a
		// condition that ended by done or maxTime), made once the recording is complete.
		if(ending != \done and: { ending != \maxTime }) { stoppedAtS = inf };
		this.prSync;
		this.prStopAudio;
		monitor.free;
		listenSynth.free;
		listenSynth = nil;  // freed once (prFreeAfterFailure)
		buttonsResponder.free;
		buttonsSynth.free;
		buttonsSynth = nil;
		pilot.free;
		this.prSync;
		conditionDevice.stopRecording;
		if(simulated.notNil) { conditionDevice.close };
		this.prSync;
		track.read.coverAll(coverage, startedAtS, stoppedAtS);
		this.log(\coverage, coverage.fraction.round(0.001));
		this.log(\coverageMap, coverage.mapString);
		if(ending == \repeat or: { ending == \abort }) { ^ending };
		^this.prQuestions
	}

	// The condition's time starts: it runs until something ends it.
	prStartRunning {
		ending = nil;
		endedBy = nil;
		conditionT0 = Main.elapsedTime;
		state = \running;
		startedAtS = this.log(\start, condition.name);
		// After the line: no report of the hand's movement can then come before it.
		if(simulated.notNil) { conditionDevice.releaseHand };
	}

	// The questions after a condition, each answer written and flushed as it is given.
	prQuestions {
		state = \questions;
		condition.questions.do { |q|
			if(ending != \abort) {
				question = q;
				answerValue = nil;
				participantWindow !? { participantWindow.ask(q) };
				experimenterWindow !? { experimenterWindow.refresh };
				if(simulated.notNil) { this.answer(simulated.answer(q, this.prStats), \simulated) };
				while { answerValue.isNil and: { ending != \abort } } { 0.05.wait };
				if(answerValue.notNil) {
					FrictionStudyFiles.appendCsv(folder +/+ "answers.csv", [participant, position + 1, condition.name,
						attempt, q.key, q.kind, answerValue[0], answerValue[1], this.prLogTime,
						FrictionStudyFiles.now], answersHeader);
					this.log(\answer, q.key);
				};
			}
		};
		question = nil;
		if(ending == \abort) { this.log(\abort); ^\abort };
		this.log(\end, condition.name);
		^\end
	}

	// Waits until the server has done what the session sent it (FrictionSync: asked again while
	// no answer comes; after lostAfterS without one the session fails, as its watch would fail it).
	prSync { FrictionSync.wait(server, lostAfterS, "FrictionStudySession " ++ participant) }

	// Ends the condition's audio.wav, all of it.
	prStopAudio { recorder !? { recorder.close; recorder = nil } }

	// The participant's output pair into the condition's audio.wav, which stops with the devices'
	// force when sclang falls silent (clientTimeoutS); the report places its first sample at the
	// recordAudio line.
	prRecordAudio {
		recorder = FrictionStudyAudio(server, conditionDir +/+ "audio.wav", participantOut, clientTimeoutS);
		this.log(\recordAudio);
		coverage = study.coverageFor(condition);
	}

	prFrame { |m|
		var area = condition.areaMm;
		if(m.positionMm >= area[0] and: { m.positionMm < area[1] }) {
			stats[\speedSum] = stats[\speedSum] + m.speedMmPerS.abs;
			stats[\speedCount] = stats[\speedCount] + 1;
		};
		m.commandedForceN !? { |f| stats[\maxForceN] = max(stats[\maxForceN], f) };
		experimenterWindow !? { experimenterWindow.frame };
	}

	prStats {
		if(stats[\trials].notNil) { ^stats.copy };
		^(meanSpeedMmPerS: stats[\speedSum] / max(1, stats[\speedCount]), maxForceN: stats[\maxForceN],
			coverage: coverage.fraction, friction: stats[\friction], audio: stats[\audio])
	}

	prInit { |argStudy, argParticipant, root, argServer, argIndex, argSeed, argDevice, argSimulated, argWindows,
		argParticipantOut, argExperimenterOut, argDeviceIndex, resuming|
		var where = "FrictionStudy.%".format(if(resuming) { "resume" } { "run" }), channels;
		if(argStudy.isKindOf(FrictionStudy).not) { Error("%: study must be a FrictionStudy".format(where)).throw };
		participant = argParticipant.asString;
		if(participant.isEmpty or: { participant.every { |c| c.isAlphaNum or: { "_-".includes(c) } }.not }) {
			Error("%: the participant code must be letters, digits, _ and -, got %".format(where,
				argParticipant.cs)).throw
		};
		FrictionStudyFiles.checkWritable(root, where);
		folder = root.standardizePath +/+ participant;
		if(resuming.not and: { File.exists(folder) }) {
			Error("%: participant code % already has a session in %; resume it (FrictionStudy.resume) or choose "
				"another code".format(where, participant, folder)).throw
		};
		if(argDevice.notNil == argSimulated.notNil) {
			Error("%: give either device (an open FrictionDevice) or simulated (a FrictionStudySimParticipant)".format(
				where)).throw
		};
		if(argDevice.notNil and: { argDevice.isKindOf(FrictionDevice).not or: { argDevice.isOpen.not } }) {
			Error("%: device must be an open FrictionDevice, got %".format(where, argDevice)).throw
		};
		if(argSimulated.notNil and: { argSimulated.isKindOf(FrictionStudySimParticipant).not }) {
			Error("%: simulated must be a FrictionStudySimParticipant, got %".format(where, argSimulated)).throw
		};
		if(argServer.isKindOf(Server).not) {
			Error("%: server must be a Server, got %".format(where, argServer)).throw
		};
		FrictionCheck.serverRunning(argServer, where);
		[\participantOut, argParticipantOut, \experimenterOut, argExperimenterOut].pairsDo { |name, bus|
			if(bus.isInteger.not or: { bus < 0 }) {
				Error("%: % must be an Integer >= 0, got %".format(where, name, bus)).throw
			}
		};
		if((argParticipantOut - argExperimenterOut).abs < 2) {
			Error("%: the participant's pair (%, %) and the experimenter's (%, %) overlap".format(where,
				argParticipantOut, argParticipantOut + 1, argExperimenterOut, argExperimenterOut + 1)).throw
		};
		channels = argServer.options.numOutputBusChannels;
		if(max(argParticipantOut, argExperimenterOut) + 2 > channels) {
			Error("%: the server has % output channels; the pairs at % and % need % (set "
				"s.options.numOutputBusChannels and reboot)".format(where, channels, argParticipantOut,
					argExperimenterOut, max(argParticipantOut, argExperimenterOut) + 2)).throw
		};
		if(argIndex.isInteger.not or: { argIndex < 0 }) {
			Error("%: participantIndex must be an Integer >= 0, got %".format(where, argIndex)).throw
		};
		if(argSeed.notNil and: { argSeed.isInteger.not }) {
			Error("%: seed must be an Integer or nil".format(where)).throw
		};
		study = argStudy;
		server = argServer;
		participantIndex = argIndex;
		seed = argSeed ?? { 2147483647.rand };
		device = argDevice;
		simulated = argSimulated;
		windows = FrictionCheck.boolean(argWindows, "windows", where);
		participantOut = argParticipantOut;
		experimenterOut = argExperimenterOut;
		deviceIndex = argDeviceIndex;
		order = study.conditionsFor(participantIndex, seed);
		File.mkdir(folder);
		if(File.exists(folder).not) { Error("%: the folder % cannot be made".format(where, folder)).throw };
	}
}
