"""The speed-against-error benchmarks (bench/run.py is the command), one module per subject:

    common          sample rate and block, the paper's numbers as the bench uses them
                    (from kfharness.profile), folders, logging, number formatting
    build           the targets the bench runs, in the build folder
    scores          the sclang score templates (sc/*.scd) and one sclang run that writes them
    timing          the NRT timing render: phases of many instances, timed by KFBenchClock
    spatial         SpatialBufRd and BufRd against the exact signal and index
    loudness        the loudness-to-force chains against equations (1) and (2)
    drift           the same after a long render, and the 10^9-sample Catch2 test
    native          the C++ benchmarks: the logarithm choice and FrictionMouseIn's reconstruction
    realtime        scsynth on jackd's dummy driver: end to end latencies, voices until xruns
    summary, goals  the printed summary, the goals and the run-to-run numbers
    plots           the PNGs
    report          bench/REPORT.md from the template bench/REPORT.md.in
    runner          the parts in order, results.json
"""
