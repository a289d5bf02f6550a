// Bench only: per block, the wall and thread CPU seconds since this unit started, each split
// into whole seconds and a fraction: [wallWhole, wallFraction, cpuWhole, cpuFraction].
KFBenchClock : MultiOutUGen {
	*ar { ^this.multiNew('audio') }

	init { |... theInputs|
		inputs = theInputs;
		^this.initOutputs(4, rate)
	}
}
