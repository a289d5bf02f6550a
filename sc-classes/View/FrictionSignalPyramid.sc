// A signal reduced to a min/max pyramid: level k holds the minimum and maximum over blocks of 2^k
// samples, so the envelope of any span (a pixel column of FrictionView) is read from a few
// blocks, whatever the zoom. Building it visits every sample once more per level, so it runs in
// a Routine and yields now and then: a long signal is reduced without freezing the GUI.
FrictionSignalPyramid {
	var <frames, <peak, mins, maxs;

	// Fetches buffer's first channel from its server and reduces it on AppClock; then calls
	// action with the pyramid, or with nil and the reason (a String; nil when the server sent
	// nothing, as after a quit) when it could not.
	*fetch { |buffer, action|
		var server = buffer.server, channels = buffer.numChannels ? 1;
		var reduce = { |array|
			case
			{ array.isNil } { action.value(nil) }
			{ array.isEmpty } { action.value(nil, "buffer % is empty".format(buffer.bufnum)) }
			{
				Routine {
					action.value(this.fromArray(if(channels > 1) { array[0, channels ..] } { array }))
				}.play(AppClock)
			}
		};
		fork {
			try {
				FrictionSync.wait(server, where: "FrictionSignalPyramid.fetch");
				// A local server shares its buffers through a file; a remote one sends them.
				if(server.isLocal) { buffer.loadToFloatArray(action: reduce) } {
					buffer.getToFloatArray(action: reduce)
				}
			} { |error|
				action.value(nil, "could not fetch buffer %: %".format(buffer.bufnum, error.errorString))
			}
		}
	}

	// The pyramid of array (numbers, at least one). Call it in a Routine: it yields every 65536
	// samples of a level.
	*fromArray { |array| ^super.new.prBuild(array) }

	// Minimum and maximum of the samples in [frameA, frameB] (fractional frame positions), or nil
	// when the span holds no sample.
	envelope { |frameA, frameB|
		var i0 = frameA.floor.asInteger.max(0), i1 = frameB.ceil.asInteger.min(frames - 1);
		var level = 0, lo = inf, hi = -inf, levelMins, levelMaxs;
		if(i1 < i0) { ^nil };
		// The coarsest level whose blocks still fit twice into the span.
		while { (1 << (level + 1)) * 2 <= (i1 - i0 + 1) and: { level + 1 < mins.size } } { level = level + 1 };
		levelMins = mins[level]; levelMaxs = maxs[level];
		(i0 >> level).for(i1 >> level, { |k| lo = min(lo, levelMins[k]); hi = max(hi, levelMaxs[k]) });
		^[lo, hi]
	}

	levels { ^mins.size }

	printOn { |stream| stream << this.class.name << "(" << frames << " frames)" }

	prBuild { |array|
		var levelMin = array.as(FloatArray), levelMax = levelMin;
		if(levelMin.isEmpty) { Error("FrictionSignalPyramid.fromArray: the array is empty").throw };
		mins = [levelMin]; maxs = [levelMax];
		while { levelMin.size > 1 } {
			var n = (levelMin.size + 1) div: 2, lo = FloatArray.newClear(n), hi = FloatArray.newClear(n);
			n.do { |i|
				var j = min(2 * i + 1, levelMin.size - 1);
				lo[i] = min(levelMin[2 * i], levelMin[j]);
				hi[i] = max(levelMax[2 * i], levelMax[j]);
				if(i % 65536 == 65535) { 0.wait };
			};
			levelMin = lo; levelMax = hi;
			mins = mins.add(levelMin); maxs = maxs.add(levelMax);
		};
		frames = array.size;
		// The largest magnitude (at least 1e-9, so that it can scale a drawing).
		peak = max(max(levelMin[0].abs, levelMax[0].abs), 1e-9);
	}
}
