"""OpenABLE: visual place recognition and loop-closure detection (docs/python.md).

The compiled part is the extension openable._openable (pybind11, OpenABLE/python/*.cc); this
package re-exports it, so that every function and class is openable.<name>, and adds the
command line (python3 -m openable, openable/__main__.py).
"""


def _import_hint():
    """One line saying why the extension cannot load in this Python, and what to use instead."""
    import glob
    import os
    import sys
    try:
        from openable._build_tree import PYTHON_EXECUTABLE as built_for
    except ImportError:  # installed by pip or cmake --install
        built_for = "Debian's /usr/bin/python3 with python3-numpy"
    here = os.path.dirname(os.path.abspath(__file__))
    built = sorted(os.path.basename(p) for p in glob.glob(os.path.join(here, "_openable.*.so")))
    this = "this Python (%s, %d.%d)" % (sys.executable, *sys.version_info[:2])
    try:
        import numpy  # noqa: F401
    except ImportError:
        return ("openable needs NumPy, which %s lacks: the module was built for %s; use that, "
                "or a venv made with /usr/bin/python3 -m venv --system-site-packages "
                "(docs/python.md)" % (this, built_for))
    if built:
        return ("openable's extension %s was built for %s, not %s; use that, or a venv made "
                "with /usr/bin/python3 -m venv --system-site-packages (docs/python.md)"
                % (built[0], built_for, this))
    return None


try:
    import numpy as _numpy  # noqa: F401  (the extension imports it too)
    from openable._openable import __doc__, __version__  # noqa: F401
except ImportError:
    _hint = _import_hint()
    if _hint is None:
        raise
    raise ImportError(_hint) from None
del _numpy
from openable._openable import *  # noqa: F401,F403  (the whole public API)
from openable._openable import __doc__, __version__, InputError, snaps  # noqa: F401


def read_matrix_settings(path):
    """read_matrix_settings(path) -> dict | None

    The settings a matrix Test_OpenABLE wrote remembers: the JSON file beside it (path +
    ".json", docs/output_formats.md). None when there is none. Its "python_evaluate" member holds
    the keywords of openable.evaluate that give the run's own figures:

        s = openable.read_matrix_settings("results/run.npy")
        r = openable.evaluate(openable.read_matrix("results/run.npy"), **s["python_evaluate"])

    Raises openable.InputError, one line naming the file, when it is not such a file, when its
    sizes do not hold together, or when the matrix at path is not the size it was written with
    (a settings file beside another run's matrix): the same checks as openable_evaluate's.
    """
    import json
    import os

    from openable import _openable

    settings = os.fspath(path) + ".json"
    if not os.path.exists(settings):
        return None
    _openable._check_matrix_settings(os.fspath(path))
    try:
        with open(settings, "rb") as f:
            document = json.loads(f.read().decode("utf-8"))
    except (OSError, ValueError) as e:
        raise InputError("settings of the matrix \"%s\": %s; expected the JSON file OpenABLE "
                         "writes beside a matrix" % (settings, e.__class__.__name__)) from None
    if not isinstance(document, dict) or not isinstance(document.get("python_evaluate"), dict):
        raise InputError("settings of the matrix \"%s\": no \"python_evaluate\" object; expected "
                         "the JSON file OpenABLE writes beside a matrix" % settings)
    return document
