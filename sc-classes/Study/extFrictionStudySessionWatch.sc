// FrictionStudySession's watch of its instrument: the server, the device and sclang itself, and
// what a session that failed frees.
+ FrictionStudySession {
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
		// A /kfStatus reply (index, then FrictionDevice.statusFields) for the device the condition
		// runs on, saying it is closed, it failed (FrictionDevice.faultOf: its thread stopped, its
		// mouse or board gone or tripped) or its recording stopped by itself (a write error, a full
		// disk: the server posted why). Not in force between conditions (state is not running: a
		// simulated participant's device is closed on purpose then).
		deviceStatus = OSCFunc({ |msg|
			var polled = conditionDevice, status = FrictionDevice.statusOf(msg[3..]);
			if(state == \running and: { polled.notNil } and: { msg[2] == polled.index }) {
				case
					{ status[\open].not } { this.prLost("the device % closed under the session".format(polled)) }
					{ status[\fault].notNil } {
						this.prLost("the device % failed (%; the post window says why)".format(polled, status[\fault]))
					}
					{ status[\recording].not } {
						this.prLost("the recording of % stopped (the post window says why)".format(polled))
					}
			}
		}, '/kfStatus', server.addr);
		Routine {
			while { this.isOver.not } {
				var stoodStill;
				server.sendMsg('/sync', watchId);
				0.25.wait;
				stoodStill = this.prStoodStill;
				case
					{ stoodStill.notNil } { this.prLost(stoodStill) }
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

	// While a condition runs, the device it plays on must stay open and recording: its slot closed
	// (kfClose, a failed reopen, another client) or its recording stopped fails the session. Its
	// status is asked each tick, the reply read by prWatch's responder (not FrictionAnswers': a
	// dead server's time-out would post).
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
		// Called from another routine (the watch's), the session's stops first: nothing of it runs
		// once the session failed, the trial in flight never stored.
		if(thisThread !== routine) { routine.stop };
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
	// (a refusal is posted), and the audio is closed in a Routine of its own. (Scheduled: from the
	// watch's or the session's Routine, defer would run it there and then, waiting.)
	prFreeAfterFailure {
		AppClock.sched(0, {
			if(server.serverRunning) {
				experiment !? _.stop;
				[monitor, listenSynth, buttonsResponder, buttonsSynth, pilot].do { |x| x !? { x.free } };
				listenSynth = buttonsSynth = nil;
				recorder !? { fork { this.prStopAudio } };
				conditionDevice !? {
					if(FrictionDevice.at(server, conditionDevice.index) === conditionDevice) {
						conditionDevice.stopRecording;
						if(simulated.notNil) { conditionDevice.close }
					}
				}
			};
			nil
		})
	}

	// A person's device gets back the client watch it had before the session (the session gave
	// it clientTimeoutS for each condition).
	prReleaseDevice {
		device !? { if(device.isOpen and: { server.serverRunning }) { device.watchClient(deviceTimeoutBefore) } }
	}
}
