"""orbed_cli: the command line of the orbed mock operating room (scripts/orbed).

One module per verb (setup.py ... verify.py: HELP, DESCRIPTION, configure(parser), optional
check(args, parser), run(args, ctx)) and a few shared ones: main (the parser, dispatch),
paths (where things are, setup and build), runs (run folders, provenance, settings),
netns (private network namespaces, running testbeds), output (messages, the progress line, child
processes with their output in log files) and checks (argument types). Standard library only
(settings.py's python3-yaml is used by that script, not here).
"""
