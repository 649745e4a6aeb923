"""OpenABLE: visual place recognition and loop-closure detection (docs/python.md).

The compiled part is the extension openable._openable (pybind11, OpenABLE/python/*.cc); this
package re-exports it, so that every function and class is openable.<name>, and adds the
command line (python3 -m openable, openable/__main__.py).
"""
from openable._openable import *  # noqa: F401,F403  (the whole public API)
from openable._openable import __doc__, __version__, InputError, snaps  # noqa: F401
