// A condition's audio.wav: an output pair recorded in the server (DiskOut, 32-bit float WAV) that
// stops writing once sclang has been silent for timeoutS, as the session's devices stop their
// force and recording (FrictionDevice.watchClient). SC's Recorder records for as long as the
// server runs: after a kill -9 of sclang it went on writing the cut attempt's audio (21 s).
// sclang sends the recording synth a heartbeat every timeoutS / 4; without one for timeoutS the
// synth pauses itself, for good (a session whose client stood still has failed). The file is
// closed by close, or by scsynth as it quits.
FrictionStudyAudio {
	var <server, <path, buffer, synth, heartbeat;

	*def {
		^SynthDef(\kfStudyAudio, { |bufnum, in, timeoutS = 0, t_alive = 0|
			DiskOut.ar(bufnum, In.ar(in, 2));
			PauseSelf.kr((timeoutS > 0) * (Sweep.kr(t_alive) > timeoutS));
		})
	}

	// Starts recording the pair from bus `in` into path; from a Routine (it waits for the server).
	// Returns once the synth plays: the file's first sample is this moment's.
	*new { |server, path, in, timeoutS = 2| ^super.newCopyArgs(server, path).prStart(in, timeoutS) }

	prStart { |in, timeoutS|
		var where = "FrictionStudyAudio";
		FrictionCheck.finite(timeoutS, "timeoutS", where);
		if(timeoutS < 0) { Error("%: timeoutS must be >= 0, got %".format(where, timeoutS)).throw };
		// The server's own recorder buffer size: 2^16 frames at 48 kHz, half of it a write.
		buffer = Buffer.alloc(server, server.sampleRate.nextPowerOfTwo, 2);
		this.class.def.send(server);
		FrictionSync.wait(server, where: "FrictionStudyAudio");
		buffer.write(path, "wav", "float", 0, 0, true);
		FrictionSync.wait(server, where: "FrictionStudyAudio");
		synth = Synth.tail(RootNode(server), \kfStudyAudio, [\bufnum, buffer, \in, in, \timeoutS, timeoutS]);
		FrictionSync.wait(server, where: "FrictionStudyAudio");
		if(timeoutS > 0) {
			heartbeat = Routine { loop { (timeoutS / 4).wait; synth.set(\t_alive, 1) } }.play(SystemClock)
		};
	}

	isRecording { ^synth.notNil }

	// Ends the file, all of it, and frees the buffer; from a Routine. DiskOut's last part (up to
	// half its buffer, 0.68 s at 48 kHz) reaches the file from scsynth's disk thread after the synth
	// is freed: a close that came first lost it (a 0.4 s condition left 0 frames). So the synth goes
	// first, and the file is closed once its size has stopped growing (at most 2 s), then the
	// buffer freed: its number goes back to sclang only once the server no longer uses it (a
	// recording started meanwhile got a number still being freed, and its file stayed 0 bytes).
	close {
		var size = -1, stableSince = Main.elapsedTime, t0 = Main.elapsedTime;
		if(synth.isNil) { ^this };
		heartbeat !? _.stop;
		heartbeat = nil;
		synth.free;
		synth = nil;
		FrictionSync.wait(server, where: "FrictionStudyAudio");
		while { Main.elapsedTime - stableSince < 0.05 and: { Main.elapsedTime - t0 < 2 } } {
			var now = File.fileSize(path);
			if(now != size) { size = now; stableSince = Main.elapsedTime };
			0.01.wait
		};
		buffer.close;
		FrictionSync.wait(server, where: "FrictionStudyAudio");
		buffer.free;
		buffer = nil;
	}

	printOn { |stream| stream << this.class.name << "(" << path.asCompileString << ")" }
}
