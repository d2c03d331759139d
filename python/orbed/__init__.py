"""orbed's Python side: the study's analysis (orbed.study) on the files the C++ tools write.

Scripts import it without an install step:

    sys.path.insert(0, os.path.join(<repo>, "python"))
    from orbed.study import analysis

Runs on Debian's /usr/bin/python3 with python3-pandas, python3-scipy and python3-statsmodels
(`scripts/orbed setup` installs them).
"""
