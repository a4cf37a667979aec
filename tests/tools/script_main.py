"""What the tests of tools/scripts share: their command line (the siviflow binary, the source
tree, a work folder and the variables for the siviflow the script starts) and a script's main()
run in this process as its own command line would run it.

usage of a test: python3 -B TEST.py SIVIFLOW SOURCE WORK [--env VAR=VALUE ...]
  (-B: no bytecode written into the source tree)
  The script runs in this process; the --env variables reach only the siviflow it starts (a
  sanitizer's preload is for siviflow, not for Python).
"""
import contextlib
import io
import os
import pathlib
import shutil
import sys


def test_setup(script):
    """(siviflow, source, work, the script's module): --env applied, WORK emptied."""
    siviflow, source, work = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    for pair in sys.argv[5:] if sys.argv[4:5] == ["--env"] else []:
        name, value = pair.split("=", 1)
        os.environ[name] = value
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    sys.path.insert(0, str(source / "tools" / "scripts"))
    return siviflow, source, work, __import__(script)


def run_main(module, arguments):
    """(exit status, what it printed) of the script's main() with these arguments."""
    sys.argv = [module.__name__ + ".py"] + arguments
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            module.main()
    except SystemExit as end:
        message = end.code if isinstance(end.code, str) else ""
        return (1 if message else end.code or 0), printed.getvalue() + message
    return 0, printed.getvalue()
