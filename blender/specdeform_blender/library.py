"""The compiled specdeform module, found beside the add-on (a bundled copy) or on sys.path.

`specdeform` is None when it cannot be imported; `problem` then says why in one line.
"""

import os
import sys

_bundled = os.path.join(os.path.dirname(__file__), "lib")
if os.path.isdir(_bundled) and _bundled not in sys.path:
    sys.path.insert(0, _bundled)

try:
    import specdeform
except ImportError as e:
    specdeform = None
    problem = (
        f"specdeform module not loadable in Blender's Python "
        f"{sys.version_info.major}.{sys.version_info.minor}: {str(e).splitlines()[0]}"
    )
else:
    problem = ""


def cache_dir():
    """The basis cache the editor uses: $XDG_CACHE_HOME/specdeform or ~/.cache/specdeform."""
    root = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(root, "specdeform")
