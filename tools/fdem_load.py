"""Compatibility name of fdem.load (python/fdem/load.py) for scripts that put tools/ on
sys.path; new code imports the `fdem` package (`import fdem; run = fdem.open("OUT")`)."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), "..", "python"))

from fdem.load import *  # noqa: E402,F401,F403
from fdem.load import __all__  # noqa: E402,F401
