"""orbed's Python side: the study's analysis (orbed.study) on the files the C++ tools write; the
message types, the bus, logs and runs (orbed.bus, orbed.log, orbed.runs; docs/python.md).

Scripts import it without an install step:

    sys.path.insert(0, os.path.join(<repo>, "python"))
    from orbed.study import analysis

Runs on Debian's /usr/bin/python3 with python3-pandas, python3-scipy and python3-statsmodels
(`scripts/orbed setup` installs them).
"""
