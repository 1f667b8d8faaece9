"""fdem: post-processing of fdem-cl output in Python.

    import fdem
    run = fdem.open("out/blasting")      # an output folder, or OUT/NAME
    run.history                          # xarray.Dataset on `time` (NAME_history.nc)
    run.frames                           # xarray.Dataset of the Exodus frames (NAME.exo)
    run.events                           # breaks and events (NAME_events.nc) or None
    run.fragments                        # fragments per frame (NAME_fragments.nc) or None

Analytics (fdem.analytics): Gutenberg-Richter b-value by maximum likelihood, fragment
size distribution (P50, P80, Rosin-Rammler and Swebrec fits). Plots (fdem.plot) and wave
diagnostics (fdem.wave) are the bodies of tools/fdem-plot and tools/fdem-wave.
Needs numpy and netCDF4; xarray for `open` (Debian: python3-numpy, python3-netcdf4,
python3-xarray), matplotlib for the plots.
"""

from .output import Run, open  # noqa: F401  (shadows the builtin inside fdem only)
from . import analytics  # noqa: F401

__all__ = ["Run", "open", "analytics"]
__version__ = "0.1"
