"""python3 -m openable COMMAND [ARGS...]: the command-line programs of OpenABLE from Python.

Each command runs one program with the arguments as given (its own --help explains them);
the program replaces this process, so its output, progress, exit status and --json report are
exactly those of the program run directly.
"""
import os
import shutil
import sys

# command -> (program, what it does)
COMMANDS = {
    "run": ("Test_OpenABLE", "a run of a Config.txt: the distance matrix of the frames, "
                             "its images, and the evaluation when ground truth is given"),
    "evaluate": ("openable_evaluate", "precision-recall figures and the HTML report of a "
                                      "saved matrix against ground truth"),
    "sweep": ("openable_sweep", "every combination of a few settings of a Config.txt, "
                                "evaluated and ranked"),
    "snaps": ("openable_snaps", "SNAPS: a drifting visual-odometry trajectory plus loops -> "
                                "a corrected one"),
    "map": ("openable_map", "maps of places that grow by sessions: add, info, merge, query"),
}

USAGE = """usage: python3 -m openable COMMAND [ARGS...]   (or: openable COMMAND [ARGS...])
       python3 -m openable COMMAND --help

The command-line programs of OpenABLE (docs/python.md, "Command line from Python"):

{commands}

ARGS go to the program unchanged, e.g.
  python3 -m openable run Config.txt --json
  python3 -m openable evaluate --help
The programs are the ones installed with this module ({where}).
"""


def program_path(program):
    """The program installed with this package, else the build tree's, else one on PATH."""
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.path.join(here, "bin", program)]
    try:  # written by CMake into the build tree's package (OpenABLE/python/CMakeLists.txt)
        from openable import _build_tree
        candidates.append(os.path.join(_build_tree.PROGRAM_DIR, program))
    except ImportError:
        pass
    for path in candidates:
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return shutil.which(program)


def usage():
    import textwrap
    width = max(len(c) for c in COMMANDS)
    lines = []
    for command, (program, text) in COMMANDS.items():
        wrapped = textwrap.wrap("%s (%s)" % (text, program), 92 - width - 4)
        lines.append("  %-*s  %s" % (width, command, wrapped[0]))
        lines += ["  %-*s  %s" % (width, "", rest) for rest in wrapped[1:]]
    where = program_path(COMMANDS["run"][0])
    where = os.path.dirname(where) if where else "not found"
    return USAGE.format(commands="\n".join(lines), where=where)


def main(argv):
    if not argv or argv[0] in ("-h", "--help", "help"):
        sys.stdout.write(usage())
        return 0 if argv else 2
    if argv[0] in ("--version", "-V"):
        import openable
        print("openable " + openable.__version__)
        return 0
    command = argv[0]
    if command not in COMMANDS:
        sys.stderr.write("python3 -m openable: unknown command '%s'; expected one of %s "
                         "(python3 -m openable --help)\n" % (command, ", ".join(COMMANDS)))
        return 2
    program = COMMANDS[command][0]
    path = program_path(program)
    if path is None:
        sys.stderr.write("python3 -m openable %s: the program %s was not found (expected it in "
                         "the package's bin/ folder, as pip install puts it, or on PATH)\n"
                         % (command, program))
        return 1
    sys.stdout.flush()
    sys.stderr.flush()
    os.execv(path, [program] + argv[1:])
    return 1  # not reached: execv replaces this process or raises OSError


def entry_point():
    """The `openable` command pip installs (the same as python3 -m openable)."""
    sys.exit(main(sys.argv[1:]))


if __name__ == "__main__":
    entry_point()
