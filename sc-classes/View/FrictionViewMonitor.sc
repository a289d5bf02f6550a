// The server side of a FrictionView: a small monitor synth at the tail of the root node sends a
// frame (position, speed, requested and commanded force) frameRate times a second with SendReply
// at control rate, so nothing is polled per sample; a responder keeps the latest frame and the
// last historyS seconds of them, and calls action after each. After Cmd-. and a reboot the
// synth starts again.
FrictionViewMonitor {
	classvar nextReplyID = 0;

	var <server, <device, <pilot, <forceBus, <positionBus, <frameRate, <historyS, <>action;
	var <synth, <isFree = false, <running = false;
	var <positionMm = 0, <speedMmPerS = 0, <forceN, <commandedForceN, <timeS = 0, <frameCount = 0;
	var history, historyHead = 0, <historyCount = 0;
	// forceChannels: how many force channels the frames carry, 0 (none), 1 (requested) or 2.
	var <forceChannels = 0, replyID, def, defBuses, oscFunc;

	// The frames of device (a FrictionDevice or a slot index): its position and speed from
	// positionBus (a Bus: position mm, optionally speed mm/s), or nil: FrictionMouseIn on the
	// device itself; the forces from forceBus (a Bus: requested N, optionally commanded N) or none.
	// action: called after every frame kept, with the monitor and whether the frame is the first
	// since it was not running (the first frame, or a pilot's after it played again).
	*new { |device = 0, forceBus, positionBus, frameRate = 30, historyS = 6, action|
		this.checkSettings(device, forceBus, positionBus, frameRate, historyS, "FrictionViewMonitor.new");
		^super.new.prInit(device, forceBus, positionBus, nil, frameRate, historyS, action)
	}

	// The frames of a FrictionPilot: its position, speed and forces as its synth computes them
	// (its monitorBus). While the pilot does not play, frames are not kept and running is false.
	*pilot { |pilot, frameRate = 30, historyS = 6, action|
		this.checkPilot(pilot, "FrictionViewMonitor.pilot");
		this.checkSettings(pilot.device, nil, nil, frameRate, historyS, "FrictionViewMonitor.pilot");
		^super.new.prInit(pilot.device, nil, nil, pilot, frameRate, historyS, action)
	}

	// The checks of *new, shared with FrictionView so that an error names the method called.
	*checkSettings { |device, forceBus, positionBus, frameRate, historyS, where|
		FrictionCheck.deviceIndex(device, where);
		[\forceBus, forceBus, \positionBus, positionBus].pairsDo { |name, bus|
			if(bus.notNil and: { bus.isKindOf(Bus).not or: { bus.index.isNil } }) {
				Error("%: % must be a Bus (control or audio) or nil, got %".format(where, name, bus)).throw
			}
		};
		if(frameRate.isNumber.not or: { frameRate <= 0 } or: { frameRate > 100 }) {
			Error("%: frameRate must be in (0, 100] Hz, got %".format(where, frameRate)).throw
		};
		if(historyS.isNumber.not or: { historyS <= 0 } or: { historyS > 600 }) {
			Error("%: historyS must be in (0, 600] s, got %".format(where, historyS)).throw
		};
	}

	*checkPilot { |pilot, where|
		if(pilot.isKindOf(FrictionPilot).not) { Error("%: expects a FrictionPilot, got %".format(where, pilot)).throw };
	}

	// The frames kept, oldest first: [timeS, positionMm, speedMmPerS, forceN, commandedForceN].
	history {
		var size = history.size;
		^Array.fill(historyCount, { |i| history[(historyHead - historyCount + i) % size].copy })
	}

	free {
		if(isFree) { ^this };
		isFree = true;
		oscFunc.free;
		if(synth.notNil and: { server.serverRunning }) { synth.free };
		synth = nil;
		ServerTree.remove(this, server);
		CmdPeriod.remove(this);
	}

	// After Cmd-. (which frees every node) or a boot: the synth again. A pilot's synth is gone too:
	// clear what it left on its bus, so that the monitor waits for it to play again.
	doOnServerTree {
		if(isFree.not) {
			if(pilot.notNil) { pilot.monitorBus.setn(0 ! 5) };
			this.prStart
		}
	}

	cmdPeriod { synth = nil }

	printOn { |stream| stream << this.class.name << "(" << (pilot ? device) << ")" }

	// ---- private ----

	prInit { |argDevice, argForceBus, argPositionBus, argPilot, argFrameRate, argHistoryS, argAction|
		device = argDevice;
		pilot = argPilot;
		server = FrictionDevice.serverOf(device);
		forceBus = argForceBus;
		positionBus = argPositionBus;
		frameRate = argFrameRate;
		historyS = argHistoryS;
		action = argAction;
		// Fixed now: the bus may be freed before the monitor.
		forceChannels = if(pilot.notNil) { 2 } { forceBus !? { forceBus.numChannels.min(2) } ? 0 };
		// Room for historyS at frameRate, and for frames that come in a burst.
		history = Array.fill((historyS * frameRate * 1.5).ceil.asInteger + 16, { FloatArray.newClear(5) });
		replyID = nextReplyID;
		nextReplyID = nextReplyID + 1;
		// Built from the buses as they are now (they may be freed before the monitor), and again
		// when their numbers changed (a device's or a pilot's buses after a reboot).
		def = this.prDef(("frictionView" ++ replyID).asSymbol);
		defBuses = this.prBusNumbers;
		oscFunc = OSCFunc({ |msg| this.prFrame(msg) }, '/frictionView', server.addr, argTemplate: [nil, replyID]);
		oscFunc.permanent = true;  // survives Cmd-.; the synth is started again by doOnServerTree
		ServerTree.add(this, server);
		CmdPeriod.add(this);
		this.prStart;
	}

	prDef { |defName|
		var force = forceBus, pos = positionBus, rate = frameRate, busIn;
		busIn = { |bus, maxChannels|
			var n = bus.numChannels.min(maxChannels);
			if(bus.rate == \audio) { A2K.kr(InFeedback.ar(bus.index, n)) } { In.kr(bus.index, n) }.asArray
		};
		^SynthDef(defName, {
			var trig = Impulse.kr(rate);
			var frameBlocks = (ControlRate.ir / rate).round.max(1), blocks = Integrator.kr(DC.kr(1), 1);
			var x, speed, forces, running = DC.kr(1), mean;
			// The mean over the last frame (over the blocks so far, at the start).
			mean = { |sig| RunningSum.kr(sig, frameBlocks) / blocks.clip(1, frameBlocks) };
			case
			{ pilot.notNil } {
				var p = In.kr(pilot.monitorBus.index, 5);
				x = p[0]; speed = p[1]; forces = [mean.(p[2]), mean.(p[3])]; running = p[4];
			}
			{ pos.notNil } {
				var p = busIn.(pos, 2);
				x = p[0]; speed = if(p.size > 1) { p[1] } { Slope.kr(x) };
			}
			{
				var m = FrictionMouseIn.kr(if(device.isKindOf(FrictionDevice)) { device.index } { device });
				x = m[0]; speed = m[2];
			};
			if(pilot.isNil) {
				forces = if(force.notNil) { busIn.(force, 2).collect(mean) } { [] };
				forces = forces ++ (0 ! (2 - forces.size));
			};
			SendReply.kr(trig, '/frictionView', [PulseCount.kr(trig), x, speed] ++ forces ++ [running], replyID);
		})
	}

	// The bus numbers the synth reads: a device's buses and a pilot's monitorBus get new ones
	// after a reboot (FrictionDevice.forceBus, FrictionPilot.monitorBus); nil: a bus freed.
	prBusNumbers { ^[forceBus, positionBus, pilot !? { pilot.monitorBus }].collect { |bus| bus !? { bus.index } } }

	prStart {
		var buses;
		if(isFree or: { server.serverRunning.not }) { ^this };
		buses = this.prBusNumbers;
		if(buses != defBuses and: { buses.every { |n, i| n.notNil or: { defBuses[i].isNil } } }) {
			def = this.prDef(def.name);
			defBuses = buses;
		};
		synth = Synth.basicNew(def.name, server);
		// The def travels with its node, so a rebooted server (no defs) works as well.
		server.sendMsg('/d_recv', def.asBytes, synth.newMsg(RootNode(server), [], \addToTail));
	}

	// msg: /frictionView, node, replyID, frame count, position, speed, force, commanded, running.
	prFrame { |msg|
		var count = msg[3], values = msg[4..8], row, resumed;
		if(isFree) { ^this };
		// A pilot that is not playing (yet, or any more) writes nothing (its bus is cleared, and
		// running reads 0): the last frames stand. (Other sources always run.)
		if(values[4] < 0.5) { running = false; ^this };
		resumed = running.not;
		running = true;
		frameCount = frameCount + 1;
		timeS = count / frameRate;
		positionMm = values[0]; speedMmPerS = values[1];
		forceN = if(forceChannels > 0) { values[2] };
		commandedForceN = if(forceChannels > 1) { values[3] };
		row = history[historyHead % history.size];
		row[0] = timeS; row[1] = positionMm; row[2] = speedMmPerS; row[3] = values[2]; row[4] = values[3];
		historyHead = (historyHead + 1) % history.size;
		historyCount = min(historyCount + 1, history.size);
		action.value(this, resumed);
	}
}
