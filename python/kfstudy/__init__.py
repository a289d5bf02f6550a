"""The extension's own Python, installed into the extension folder (python/kfstudy there) and run
by FrictionStudy.report: what reads the files the extension writes and reports a study. The tests,
the bench and the study job import the same modules from the repository.

    readers         WAV and kf-session files
    session_folder  a FrictionStudy session folder read back, and its measurements
    psychometric    the threshold procedures' fit (maximum likelihood Weibull with a lapse rate)
    report          the study report (Markdown, PNG, CSV): a pipeline of
    report_tables   load and tidy tables (pandas),
    report_statistics  where the friction is raised and the binds statistic,
    report_figures  the figures, and
    report_text     report.md's Markdown
    __main__        python3 -m kfstudy SESSIONS REPORT: the report, its packages checked first

It needs python3 with numpy, pandas, matplotlib, scipy and soundfile (Debian: python3-numpy,
python3-pandas, python3-matplotlib, python3-scipy, python3-soundfile), and nothing of the repository.
"""
