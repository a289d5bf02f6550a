// FrictionDevice with a real USB mouse as the puck's sensor (hidapi, or Linux evdev), the list
// of mice the server sees, and mouse profiles (count size per axis from a measured stroke).
+ FrictionDevice {

	// which: nil (the first mouse), an index of listMice, a device path ("/dev/hidraw3",
	// "/dev/input/event5") or "VVVV:PPPP" / "VVVV:PPPP:serial" (hex ids). backend: \evdev (nil on
	// Linux: it opens wireless receivers' mice too) or \hidapi (nil elsewhere). profile: an Event
	// of settings (e.g. (countMm: 0.0212)) or the path of a mouse profile file (writeMouseProfile).
	// grab: evdev only, keeps the desktop cursor still. server, replace: as *sim's.
	*mouse { |server, index = 0, which, backend, profile, grab = false, replace = false|
		^this.new.prInitMouse(server ? Server.default, index, which, backend, profile, grab, replace).prOpen
	}
	// Described only, on no server: its ...Msg methods for a Score.
	*describeMouse { |index = 0, which, backend, profile, grab = false, replace = false|
		^this.new.prInitMouse(nil, index, which, backend, profile, grab, replace)
	}

	// The OSC message that opens the mouse (openMsg adds replace).
	mouseMsg {
		^['/cmd', \kfOpenMouse, index, source[\which], source[\backend].asString, source[\profilePath] ? ""]
		++ (if(source[\grab]) { [\grab, 1] } { [] })
		++ this.prOverrideArgs
	}

	// After an unplug (kfStatus says UNPLUGGED; the position holds): look for the mouse again.
	reopen { this.prSendAnswered(\kfReopenMouse, this.reopenMsg) }
	reopenMsg { ^['/cmd', \kfReopenMouse, index] }

	// Asks the server for the mice it can open; calls action with an Array of Events (backend,
	// index, path, vendorId, productId, serial, interface, name), empty when there are none.
	// backend: \hidapi, \evdev or nil (both).
	*listMice { |server, backend, action|
		var path;
		server = server ? Server.default;
		FrictionCheck.serverRunning(server, "FrictionDevice.listMice");
		path = PathName.tmp +/+ "kf-mice-%-%.txt".format(Main.elapsedTime.hash.abs, UniqueID.next);
		fork {
			var mice = [];
			// A refusal (an unknown backend, a failed enumeration) is an Error with the reason.
			FrictionAnswers.send(server, \kfListMice, nil, this.listMiceMsg(backend, path));
			if(File.exists(path)) {
				mice = File.readAllString(path).split($\n).reject(_.isEmpty).collect { |line|
					var f = line.split($\t);
					(backend: f[0].asSymbol, index: f[1].asInteger, path: f[2], vendorId: f[3], productId: f[4],
						serial: f[5], interface: f[6].asInteger, name: f[7] ? "")
				};
				File.delete(path);
			};
			action.value(mice);
		}
	}
	*listMiceMsg { |backend, path| ^['/cmd', \kfListMice, (backend ? "").asString, path ? ""] }

	// The count size (mm) of an axis: the puck moved strokeMm along a ruler while the mouse
	// summed counts (open the mouse with (countMm: 1) and FrictionMouseIn reads counts).
	*countMmFromStroke { |counts, strokeMm|
		if(counts.isNumber.not or: { counts == 0 }) {
			Error("FrictionDevice.countMmFromStroke: the mouse counted nothing (%)".format(counts)).throw
		};
		if(strokeMm.isNumber.not or: { strokeMm <= 0 }) {
			Error("FrictionDevice.countMmFromStroke: strokeMm must be a positive length, got %".format(strokeMm)).throw
		};
		^strokeMm / counts.abs
	}
	// The maker's counts per inch as a count size: a starting value before a stroke.
	*countMmFromCpi { |cpi| ^25.4 / cpi }

	// A mouse profile file ("key = value" lines; device/mouse/MouseProfile.hpp reads the same).
	*writeMouseProfile { |path, profile|
		var file = File(path.standardizePath, "w");
		if(file.isOpen.not) { Error("FrictionDevice.writeMouseProfile: cannot write %".format(path)).throw };
		file.write("# kf-mouse-profile 1\n");
		[\name, \vendorId, \productId, \serial, \surface, \cpi, \countMmX, \countMmY, \updateRateHz, \swapXY, \signX,
			\signY].do { |key|
			profile[key] !? { |value| file.write("% = %\n".format(key, value)) }
		};
		file.close;
	}
	*readMouseProfile { |path|
		var profile = (), text;
		path = path.standardizePath;
		if(File.exists(path).not) { Error("FrictionDevice.readMouseProfile: no such file: %".format(path)).throw };
		text = File.readAllString(path);
		text.split($\n).do { |line, i|
			var equals, key, value;
			line = line.stripWhiteSpace;
			if(line.notEmpty and: { line[0] != $# }) {
				equals = line.find("=");
				if(equals.isNil) { Error("%:%: not 'key = value'".format(path, i + 1)).throw };
				key = line.keep(equals).stripWhiteSpace.asSymbol;
				value = line.drop(equals + 1).stripWhiteSpace;
				profile[key] = case { [\cpi, \countMmX, \countMmY, \updateRateHz].includes(key) } {
					value.asFloat
				} { [\swapXY, \signX, \signY].includes(key) } {
					value.asInteger
				} { value };
			}
		};
		^profile
	}
	// The device settings a profile gives: countMm (measured, else from cpi), updateRate.
	*mouseProfileSettings { |profile|
		var settings = ();
		(profile[\countMmX] ?? { profile[\cpi] !? { |cpi| this.countMmFromCpi(cpi) } }) !? { |mm|
			settings[\countMm] = mm
		};
		profile[\updateRateHz] !? { |hz| settings[\updateRate] = hz };
		^settings
	}

	prInitMouse { |argServer, argIndex, which, backend, profile, grab, replace = false|
		var settings, profilePath;
		backend = backend ?? { if(thisProcess.platform.name == \linux) { \evdev } { \hidapi } };
		if([\hidapi, \evdev].includes(backend.asSymbol).not) {
			Error("FrictionDevice.mouse: backend must be \\hidapi or \\evdev, got %".format(backend)).throw
		};
		if(which.notNil and: { which.isString.not and: { which.isInteger.not } }) {
			Error("FrictionDevice.mouse: which must be nil, an index, a path or \"VVVV:PPPP\", got %".format(
				which)).throw
		};
		if(profile.isString) {
			profilePath = profile.standardizePath;
			settings = this.class.mouseProfileSettings(this.class.readMouseProfile(profilePath));
		} {
			settings = profile
		};
		this.prInit(argServer, argIndex, \mouse, (which: (which ? "").asString, backend: backend.asSymbol,
			profilePath: profilePath, grab: grab == true), settings, replace);
	}
}
