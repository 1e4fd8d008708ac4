"""plot-run's one way to stop on bad input: a message naming what is wrong, exit status 2."""
import sys


def fail(message):
    sys.stderr.write("plot-run: %s\n" % message)
    sys.exit(2)
