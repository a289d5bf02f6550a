// FrictionDevice's audio drive (FrictionDrive, docs/drive-format.md): the magnet driven from a
// DC-coupled audio output through a current source, with a calibration loaded on the server.
// Answered as every device command (FrictionAnswers); the device loads it again after a reboot.
+ FrictionDevice {

	// path: a kf-drive file (the circuit, naming its magnet table); nil: no drive (FrictionDrive
	// outputs 0). The server refuses a file whose numbers disagree, with the reason.
	loadDrive { |path|
		this.prSendAnswered(\kfDriveCalibrate, this.loadDriveMsg(path), {
			driveSetup = path !? { (path: path.standardizePath,
				circuitLatencyS: this.class.driveCircuitLatencyOf(path.standardizePath)) };
		})
	}
	loadDriveMsg { |path|
		if(path.notNil and: { path.isString.not }) {
			Error("FrictionDevice.loadDrive: path must be a String or nil, got %".format(path)).throw
		};
		^['/cmd', \kfDriveCalibrate, index, path !? { path.standardizePath } ? ""]
	}

	// The audio drive's latency beside the audio path (both leave through the interface): one
	// server block (FrictionDrive drives the previous block's force) plus the current source's
	// and the magnet's declared delays, in s; nil without a drive.
	driveLatency {
		^driveSetup !? { |d|
			server.options.blockSize / (server.sampleRate ? server.options.sampleRate ? 48000) + d[\circuitLatencyS]
		}
	}

	// currentSourceLatencyS + magnetLagS of a kf-drive file (the server checked it). Fields are
	// split at any white space (spaces, tabs, CR), as the server's reader (DriveCircuit.cpp) does.
	*driveCircuitLatencyOf { |path|
		var sum = 0;
		File.readAllString(path).split($\n).do { |line|
			var fields = line.split($#).first.collect { |c| if(c.isSpace) { $  } { c } }.split($ ).reject(_.isEmpty);
			if(fields.size == 2 and: { [\currentSourceLatencyS, \magnetLagS].includes(fields[0].asSymbol) }) {
				sum = sum + fields[1].asFloat
			}
		};
		^sum
	}
}
