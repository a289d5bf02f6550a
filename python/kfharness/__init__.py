"""The project's Python harness: one home for what the tests, the benchmarks and the main job
share. Importing any module here has no side effects (no folders made, no environment read
until a function asks).

    paths      where the repository, the extension folder, the test data and the work folder are
    profile    the paper's device profile (profiles/paper.json), the one source of its numbers
    procs      processes by pid: alive, descendants, stop; free UDP ports
    sclang     headless sclang: environment, class paths, scripts with or without a booted server
    nrt        scsynth -N renders of Scores
    jack       a JACK server on the dummy driver
    reference  numeric references: equations (1) and (2), zero crossings

The files the extension writes are read by python/kfstudy (readers, the study report, the
psychometric fit), which is installed into the extension folder.
"""
