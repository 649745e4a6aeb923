"""OpenABLE: visual place recognition and loop-closure detection (docs/python.md).

The compiled part is the extension openable._openable (pybind11, OpenABLE/python/*.cc); this
package re-exports it, so that every function and class is openable.<name>, and adds the
command line (python3 -m openable, openable/__main__.py).
"""
from openable._openable import *  # noqa: F401,F403  (the whole public API)
from openable._openable import __doc__, __version__, InputError, snaps  # noqa: F401


def read_matrix_settings(path):
    """read_matrix_settings(path) -> dict | None

    The settings a matrix Test_OpenABLE wrote remembers: the JSON file beside it (path +
    ".json", docs/output_formats.md). None when there is none. Its "python_evaluate" member holds
    the keywords of openable.evaluate that give the run's own figures:

        s = openable.read_matrix_settings("results/run.npy")
        r = openable.evaluate(openable.read_matrix("results/run.npy"), **s["python_evaluate"])

    Raises openable.InputError, one line naming the file, when it is not such a file.
    """
    import json
    import os

    settings = os.fspath(path) + ".json"
    if not os.path.exists(settings):
        return None
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
