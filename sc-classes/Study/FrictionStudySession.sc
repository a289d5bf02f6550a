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
FrictionStudySession {
	classvar <answersHeader, <eventsHeader, <trialsHeader;
	// A server that has not answered a /sync for this long (s) is lost: the session fails.
	classvar <>lostAfterS = 3;
	// The client watch of the devices a session plays on (FrictionDevice.watchClient): a server
	// that has not heard this sclang for this long (s) turns the force off. 0: no watch.
	classvar <>clientTimeoutS = 2;
	var <study, <participant, <folder, <server, <participantIndex, <seed, <device, <simulated, <windows;
	var <participantOut, <experimenterOut, <deviceIndex;
	var <order, <position = 0, <state = \ready, <condition, <conditionDevice, <pilot, <coverage, <monitor;
	var <conditionDir, <attempt = 0, <question, <endedBy, <paused = false, <stats;
	var <participantWindow, <experimenterWindow, <>onEnd;
	var lastPositionMm, ending, answerValue, listenSynth, recorder, preparedT0, conditionT0, pausedS = 0, pauseT0;
	var buttonsSynth, buttonsResponder;
	var routine, lastAnswerT, watchTickT, watchId, experiment, sessionTimeOffsetS = 0, deviceTimeoutBefore;

	*initClass {
		answersHeader = #[participant, position, condition, attempt, question, kind, answer, source, timeS, wallTime];
		eventsHeader = #[timeS, event, detail, wallTime];
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

	// A line in the condition's events.csv, with the time since its prepare line.
	log { |event, detail = ""|
		conditionDir !? {
			FrictionStudyFiles.appendCsv(conditionDir +/+ "events.csv",
				[this.prLogTime, event, detail, FrictionStudyFiles.now], eventsHeader)
		}
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
				server.sync;
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
		var s = condition.settings;
		preparedT0 = Main.elapsedTime;
		conditionT0 = nil;
		pausedS = 0;
		paused = false;
		attempt = this.prLastAttempt(position) + 1;
		conditionDir = this.prConditionDir(position, attempt);
		File.mkdir(conditionDir);
		this.log(\prepare, condition.name);
		state = \preparing;
		conditionDevice = if(simulated.notNil) {
			FrictionDevice.sim(server, deviceIndex, simulated.handFor(condition), replace: true)
		} { device };
		conditionDevice.record(conditionDir +/+ "device.kfsession");
		this.log(\recordDevice);
		if(clientTimeoutS > 0) { conditionDevice.watchClient(clientTimeoutS) };
		if(condition.isThreshold) { ^this.prRunThreshold };
		pilot = FrictionPilot(conditionDevice, s[\mapping], s[\friction], s[\origin], if(s[\audio]) { s[\amp] } { 0 },
			participantOut);
		pilot.play;
		server.sync;
		listenSynth = Synth.after(pilot.synth, \frictionStudyListen, [\in, participantOut, \out, experimenterOut]);
		buttonsSynth = Synth.tail(server, \frictionStudyButtons, [\device, conditionDevice.index]);
		buttonsResponder = OSCFunc({ this.done(\button) }, '/kfStudyButton', server.addr,
			argTemplate: [buttonsSynth.nodeID]);
		this.prRecordAudio;
		stats = (speedSum: 0, speedCount: 0, maxForceN: 0, friction: s[\friction], audio: s[\audio]);
		// 50 frames a second; the cells between two frames are covered too (FrictionStudyCoverage).
		lastPositionMm = nil;
		monitor = FrictionViewMonitor.pilot(pilot, 50, 6, { |m, resumed| this.prFrame(m, resumed) });
		participantWindow !? { participantWindow.showInstruction(condition.instruction) };
		experimenterWindow !? { experimenterWindow.showCondition };
		ending = nil;
		endedBy = nil;
		conditionT0 = Main.elapsedTime;
		state = \running;
		this.log(\start, condition.name);
		while { ending.isNil } {
			0.05.wait;
			if(paused.not) {
				if(simulated.notNil and: { simulated.isDone(coverage, this.elapsedS, condition) }) {
					this.done(\participant)
				};
				if(ending.isNil and: { this.elapsedS >= condition.maxTimeS }) { ending = \maxTime; endedBy = \time };
			};
		};
		state = \stopping;
		this.log(ending, endedBy ? "");
		this.log(\coverage, coverage.fraction.round(0.001));
		this.prStopAudio;
		monitor.free;
		listenSynth.free;
		listenSynth = nil;  // freed once (prFreeAfterFailure)
		buttonsResponder.free;
		buttonsSynth.free;
		buttonsSynth = nil;
		pilot.free;
		server.sync;
		conditionDevice.stopRecording;
		if(simulated.notNil) { conditionDevice.close };
		server.sync;
		if(ending == \repeat or: { ending == \abort }) { ^ending };
		^this.prQuestions
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

	// A threshold condition: the experiment's trials (each a line of trials.csv, flushed), its
	// estimate in the events, then the questions. The experiment plays on the participant's pair. A
	// simulated participant answers through the condition's makeObserver, or its own observer for
	// the experiment's kind; the experiment and the observer (its known threshold) are logged.
	prRunThreshold {
		var estimate, how, stored, right = 0, count = 0;
		experiment = condition.makeExperiment.value;
		how = if(simulated.notNil) {
			condition.makeObserver !? { |make| make.value(simulated.seed) } ?? {
				if(experiment.respondsTo(\kind).not) {
					Error("threshold condition %: no makeObserver, and the experiment has no kind for the simulated "
						"participant's observer".format(condition.name)).throw
				};
				simulated.observerFor(experiment.kind)
			}
		} { condition.answers };
		if(experiment.respondsTo(\asEvent)) { this.log(\experiment, FrictionStudyFiles.json(experiment.asEvent)) };
		if(how.respondsTo(\asEvent)) { this.log(\observer, FrictionStudyFiles.json(how.asEvent)) };
		// A resumed attempt goes on from the trials stored before: the procedure (and a simulated
		// participant's observer) as it was when the session stopped.
		stored = this.prStoredTrials;
		if(stored.notEmpty) {
			experiment.continueFrom(stored, if(how.isKindOf(FrictionObserver)) { how });
			count = stored.size;
			right = stored.count { |t| t[\correct] == "true" };
			this.log(\continue, this.prJoined(stored))
		};
		listenSynth = Synth.tail(server, \frictionStudyListen, [\in, participantOut, \out, experimenterOut]);
		this.prRecordAudio;
		participantWindow !? {
			participantWindow.showInstruction(condition.instruction);
			participantWindow.doneButton.visible = false;  // the experiment ends it
		};
		experimenterWindow !? { experimenterWindow.refresh };
		ending = nil;
		endedBy = nil;
		conditionT0 = Main.elapsedTime;
		state = \running;
		this.log(\start, condition.name);
		estimate = experiment.run(conditionDevice, how, { |trial|
			var endT = Main.elapsedTime;
			// Stored once the server has answered since the trial ended (a round trip: a few ms): a
			// trial that ended on a lost server is never stored (prLost ends the session meanwhile).
			server.sendMsg('/sync', watchId);
			while { lastAnswerT <= endT and: { Main.elapsedTime - endT < lostAfterS } } { 0.005.wait };
			// No answer (the watch gone with Cmd-., say): the trial is not stored, the session fails.
			if(lastAnswerT <= endT) { Error("the server did not answer after trial %".format(trial[\trial])).throw };
			// sclang stood still during the trial (the watch did not tick): its times are not the
			// participant's; it is not stored, whichever of the two routines runs first after it.
			this.prStoodStill !? { |reason| this.prLost(reason) };
			FrictionStudyFiles.appendCsv(folder +/+ "trials.csv", [participant, position + 1, condition.name, attempt]
				++ #[trial, level, target, answer, correct, startS, interval1S, interval2S, answerS].collect { |k|
					trial[k] } ++ [FrictionStudyFiles.now], trialsHeader);
			this.log(\trial, trial[\trial]);
			count = count + 1;
			if(trial[\correct] == true) { right = right + 1 };
		}, nil, participantOut);
		endedBy = \procedure;
		this.log(\done, \procedure);
		this.log(\estimate, FrictionStudyFiles.json(estimate));
		stats = (trials: count, correct: right);
		state = \stopping;
		this.prStopAudio;
		listenSynth.free;
		listenSynth = nil;  // freed once (prFreeAfterFailure)
		server.sync;
		conditionDevice.stopRecording;
		if(simulated.notNil) { conditionDevice.close };
		server.sync;
		^this.prQuestions
	}

	// The trials an earlier attempt at this threshold condition stored, which this attempt goes on
	// from: per trial number the row of the latest attempt that has it, from trial 1 to the first
	// number none has (a damaged row: the procedure goes on from there). The report joins them so.
	prStoredTrials {
		var mine, byTrial = (), n = 1, stored = [];
		if(attempt < 2) { ^[] };
		mine = FrictionStudyFiles.readCsv(folder +/+ "trials.csv").select { |t|
			t[\position] == (position + 1).asString and: { t[\condition] == condition.name.asString }
		};
		mine.sort { |a, b| a[\attempt].asInteger <= b[\attempt].asInteger }.do { |t| byTrial[t[\trial].asInteger] = t };
		while { byTrial[n].notNil } { stored = stored.add(byTrial[n]); n = n + 1 };
		^stored
	}

	// How stored trials join: "1-8 of attempt 1, 9-12 of attempt 2".
	prJoined { |stored|
		var parts = stored.separate { |a, b| a[\attempt] != b[\attempt] };
		^parts.collect { |p| "%-% of attempt %".format(p.first[\trial], p.last[\trial], p.first[\attempt]) }.join(", ")
	}

	// ---- the instrument ----

	// Every 0.25 s the server is sent a /sync; its /synced comes after its audio thread ran a
	// block, so a server that died, quit, hangs or lost its audio (jackd gone) sends none. With
	// no answer for lostAfterS the session fails at once (prLost). 3 s: the server's async queue
	// (a file opened for recording, a SynthDef) holds a /sync back beside it; a false alarm would
	// end a participant's session, so the bound is far above the round trip (a few ms). The same
	// tick finds sclang itself standing still (prStoodStill) and, while a condition runs, a
	// device whose slot closed (prWatchDevice).
	prWatch {
		var answered, deviceStatus;
		watchId = UniqueID.next;
		lastAnswerT = watchTickT = Main.elapsedTime;
		answered = OSCFunc({ lastAnswerT = Main.elapsedTime }, '/synced', server.addr, argTemplate: [watchId]);
		// A /kfStatus reply (index, then FrictionDevice.statusFields: open first) for the device the
		// condition runs on, saying it is closed. Not in force between conditions (state is not
		// running: a simulated participant's device is closed on purpose then).
		deviceStatus = OSCFunc({ |msg|
			var polled = conditionDevice;
			if(state == \running and: { polled.notNil } and: { msg[2] == polled.index } and: { msg[3] == 0 }) {
				this.prLost("the device % closed under the session".format(polled))
			}
		}, '/kfStatus', server.addr);
		Routine {
			while { this.isOver.not } {
				server.sendMsg('/sync', watchId);
				0.25.wait;
				case
					{ this.prStoodStill.notNil } { this.prLost(this.prStoodStill) }
					{ Main.elapsedTime - lastAnswerT > lostAfterS } {
						this.prLost("the server % stopped answering (no /synced for % s)".format(server.name,
							(Main.elapsedTime - lastAnswerT).round(0.01)))
					}
					{ this.prWatchDevice };
				watchTickT = Main.elapsedTime;
			};
			answered.free;
			deviceStatus.free;
		}.play(AppClock);
	}

	// A reason if the watch's 0.25 s tick came more than lostAfterS late: sclang did not run
	// meanwhile (the computer slept, sclang was stopped). The participant's times and the trial
	// in flight cannot be trusted; the server's answers, which did not come, would be blamed.
	prStoodStill {
		var still = Main.elapsedTime - watchTickT;
		^if(still > (lostAfterS + 0.25)) {
			"sclang stood still for % s (the computer asleep, or sclang stopped)".format(still.round(0.01))
		}
	}

	// While a condition runs, the device it plays on must stay open: its slot closed (kfClose, a
	// failed reopen, another client) fails the session. Its status is asked each tick, the reply
	// read by prWatch's responder (not FrictionAnswers': a dead server's time-out would post).
	prWatchDevice {
		if(state == \running and: { conditionDevice.notNil }) { server.listSendMsg(conditionDevice.statusMsg(false)) }
	}

	// The instrument is gone: the session fails with the reason in session.csv, the condition's
	// events and the post window, and its routine, which may be waiting on that server, stops
	// (last: called from inside that routine, its stop does not return). What was stored stays;
	// the trial in flight is not stored.
	prLost { |reason|
		if(this.isOver) { ^this };
		state = \failed;
		this.log(\lost, reason);
		this.prSessionLog(\error, reason);
		"FrictionStudySession %: %; the session failed (what it stored is kept)".format(participant, reason).error;
		participantWindow !? { participantWindow.showEnd };
		experimenterWindow !? { experimenterWindow.refresh };
		onEnd.value(this);
		this.prFreeAfterFailure;  // a server that still runs (jackd gone, a hang) plays on otherwise
		this.prReleaseDevice;
		routine.stop;
	}

	// A session that failed frees what its condition started: the experiment's stimulus and
	// answers, the synths, the audio recording, the device's recording, the simulated device
	// (which the next session may then open). Without waiting for the server, which may be why it
	// failed: from AppClock outside a Routine the device's commands do not wait for their answers
	// (a refusal is posted), and the audio is closed in a Routine of its own.
	prFreeAfterFailure {
		{
			if(server.serverRunning) {
				experiment !? { if(experiment.respondsTo(\stop)) { experiment.stop } };
				[monitor, listenSynth, buttonsResponder, buttonsSynth, pilot].do { |x| x !? { x.free } };
				listenSynth = buttonsSynth = nil;
				recorder !? { fork { this.prStopAudio } };
				conditionDevice !? {
					if(FrictionDevice.at(server, conditionDevice.index) === conditionDevice) {
						conditionDevice.stopRecording;
						if(simulated.notNil) { conditionDevice.close }
					}
				}
			}
		}.defer
	}

	// A person's device gets back the client watch it had before the session (the session gave
	// it clientTimeoutS for each condition).
	prReleaseDevice {
		device !? { if(device.isOpen and: { server.serverRunning }) { device.watchClient(deviceTimeoutBefore) } }
	}

	// Ends the condition's audio.wav. Recorder.stopRecording frees its DiskOut and closes the file
	// in one go, but DiskOut's last part (up to half its buffer, 0.68 s at 48 kHz) reaches the file
	// from scsynth's disk thread after the free: a close that came first lost it (a 0.4 s condition
	// left 0 frames). So the DiskOut goes first, without the Recorder's own close on its /n_end (its
	// onFree, a dependant of the node); the file is closed once its size has stopped growing (the
	// disk thread wrote), at most 2 s later. Recorder has no flush of its own to call instead.
	prStopAudio {
		var path = recorder.path, size = -1, stableSince = Main.elapsedTime, t0 = Main.elapsedTime;
		if(path.isNil) { ^this };  // closed already
		if(recorder.isRecording.not or: { Recorder.instVarNames.includes(\recordNode).not }) {
			^recorder.stopRecording
		};
		recorder.instVarAt(\recordNode) !? { |node| node.releaseDependants; node.free };
		server.sync;
		while { Main.elapsedTime - stableSince < 0.05 and: { Main.elapsedTime - t0 < 2 } } {
			var now = File.fileSize(path);
			if(now != size) { size = now; stableSince = Main.elapsedTime };
			0.01.wait
		};
		recorder.stopRecording;
	}

	// The participant's output pair into the condition's audio.wav; the report places its first
	// sample at the recordAudio line.
	prRecordAudio {
		recorder = Recorder(server).recHeaderFormat_("wav").recSampleFormat_("float");
		recorder.record(conditionDir +/+ "audio.wav", participantOut, 2);
		server.sync;
		while { recorder.isRecording.not } { 0.01.wait };
		this.log(\recordAudio);
		coverage = study.coverageFor(condition);
	}

	prFrame { |m, resumed|
		var area = condition.areaMm;
		if(resumed == true) { lastPositionMm = nil };
		coverage.add(lastPositionMm ? m.positionMm, m.positionMm, m.speedMmPerS);
		lastPositionMm = m.positionMm;
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

	// Every threshold condition's stimuli against the device's range before the session starts
	// (FrictionThreshold.checkRange): a level the device would clamp is refused now, not when its
	// condition comes. The simulated participant's devices have the paper's specs.
	prCheckStimuli {
		var specs = device !? _.specs ?? { FrictionDevice.paperSpecs };
		order.select(_.isThreshold).do { |c|
			var experiment = c.makeExperiment.value;
			if(experiment.respondsTo(\checkRange)) {
				try { experiment.checkRange(specs, device ? "the simulated device") } { |error|
					Error("FrictionStudy: condition %: %".format(c.name, error.what)).throw
				}
			}
		}
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
