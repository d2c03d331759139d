"""python3 -m orbed.study STUDY_DIR: the study's analysis into STUDY_DIR/tables.json (analysis.py),
the summary on stdout. Exit 0, 2 on bad arguments, 1 when the folder cannot be read."""
import sys

from . import analysis


def main(argv):
    if len(argv) != 1 or argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    try:
        tables = analysis.write(argv[0])
    except (OSError, ValueError, KeyError) as e:
        print("orbed.study: %s" % e, file=sys.stderr)
        return 1
    sys.stdout.write(analysis.summary(tables))
    return 0


sys.exit(main(sys.argv[1:]))
