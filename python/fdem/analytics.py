"""Fracture analytics: Gutenberg-Richter b-value and fragment size distributions.

b-value (magnitude-frequency of events)
    The Gutenberg-Richter law says the number of events of magnitude M or more falls as
    log10 N(>= M) = a - b M. `b_value` is Aki's (1965) maximum-likelihood estimate over
    the events at or above the magnitude of completeness Mc,

        b = log10(e) / (mean(M) - (Mc - dm/2)),

    where dm is the width of the magnitude bins when the magnitudes are rounded to
    multiples of dm (Utsu's 1966 correction: a binned magnitude Mc stands for the events
    from Mc - dm/2 up), and dm = 0 for continuous magnitudes (fdem-cl's event magnitudes
    are continuous). Its standard error is Shi and Bolt's (1982)
    2.3 b^2 sqrt(sum (M - mean)^2 / (n (n - 1))), and a = log10 n + b Mc so that
    10^(a - b M) counts the events of magnitude M or more above Mc. `completeness_magnitude`
    gives Mc by maximum curvature: the lower edge of the most populated bin.
    Too few events for an estimate (fewer than 2 at or above Mc, or all of them at Mc,
    or none at all) is not an error: `b_value` then returns b = a = b_error = NaN with
    the reason in `note` (and `ok` False), so a catalogue of one event gives an answer
    that says so rather than an exception in the middle of a script.

Fragment size distribution (mass passing)
    P(x) is the mass fraction of fragments of size x or finer (the "passing" curve of a
    sieve analysis). `passing` gives it at each fragment size; `percentile_size(.., 0.5)`
    is P50 and `(.., 0.8)` P80: the size of the fragment at which P first reaches the
    fraction (the inverse of the step function P; no interpolation between fragment
    sizes, since there is no mass between them: when one large piece holds most of the
    mass, P50 is its size, not a size in the gap below it).
    Fits, by least squares on the curve's midpoints P_i - m_i / (2 M) (Hazen's plotting
    position, which keeps the largest fragment off P = 1):
      Rosin-Rammler  P(x) = 1 - exp(-(x/x_c)^n), a straight line ln(-ln(1-P)) =
                     n ln x - n ln x_c;
      Swebrec        P(x) = 1 / (1 + [ln(x_max/x) / ln(x_max/x50)]^b): for a given x_max,
                     ln(1/P - 1) = b ln ln(x_max/x) - b ln ln(x_max/x50) is a straight
                     line; x_max is the one whose line misses the curve P least, searched
                     between the largest fragment and ten times it (on a grid of
                     ln ln(x_max/x_largest), refined by golden section): the Swebrec
                     x_max is a largest size, not a free shape parameter.
                     When the best x_max is an end of that range (the largest fragment
                     itself, or ten times it) the curve has no Swebrec-shaped best
                     within it: the fit says which end in `bound` ("lower", "upper")
                     and warns (FitWarning); give `xmax` to fix it instead.
"""

import warnings
from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

__all__ = ["BValue", "FitWarning", "b_value", "completeness_magnitude", "magnitude_from_energy",
           "magnitude_frequency",
           "passing", "percentile_size", "RosinRammler", "Swebrec", "rosin_rammler_fit",
           "swebrec_fit", "SizeDistribution", "size_distribution", "equivalent_diameter"]

LOG10_E = float(np.log10(np.e))


class FitWarning(UserWarning):
    """A fit was made but is not to be trusted as it stands (e.g. a Swebrec x_max on the
    bound of its search)."""


# ---------------------------------------------------------------------------------------
# Gutenberg-Richter

@dataclass
class BValue:
    b: float         # Gutenberg-Richter b
    b_error: float   # Shi and Bolt's standard error of b
    a: float         # log10 of the number of events of magnitude >= 0 on the fitted line
    mc: float        # magnitude of completeness used
    dm: float        # bin width used (0: continuous magnitudes)
    n: int           # events at or above Mc
    note: str = ""   # why b is NaN (too few events); empty when b was estimated

    @property
    def ok(self) -> bool:
        """Whether b was estimated (False: too few events, see `note`)."""
        return not self.note

    def count_at_least(self, m):
        """Events of magnitude m or more on the fitted line, 10^(a - b m)."""
        return 10.0 ** (self.a - self.b * np.asarray(m, dtype=float))


def _finite(values) -> np.ndarray:
    v = np.asarray(values, dtype=float).ravel()
    return v[np.isfinite(v)]


def completeness_magnitude(magnitudes, bin_width: float = 0.1) -> float:
    """Mc by maximum curvature: the lower edge of the most populated magnitude bin, bins
    of `bin_width` with edges at its multiples (the lowest such bin on a tie)."""
    m = _finite(magnitudes)
    if len(m) == 0:
        raise ValueError("no magnitudes")
    if not bin_width > 0:
        raise ValueError(f"bin width must be > 0 (got {bin_width})")
    # A small tolerance so that a magnitude on an edge (k*dm in binary) counts above it.
    index = np.floor(m / bin_width + 1e-9).astype(np.int64)
    values, counts = np.unique(index, return_counts=True)
    return float(values[np.argmax(counts)] * bin_width)


def b_value(magnitudes, mc: Optional[float] = None, dm: float = 0.0,
            bin_width: float = 0.1) -> BValue:
    """Aki's maximum-likelihood b over the magnitudes >= Mc (module docstring).
    mc: magnitude of completeness; None: completeness_magnitude(magnitudes, bin_width).
    dm: width of the bins the magnitudes are rounded to (0 for continuous ones); with
    dm > 0 the events of the bins from Mc up are used (M >= Mc - dm/2).
    With too few events (none, one, or all at Mc) the result has b, b_error and a NaN
    and says why in `note` (`ok` is False); bad arguments raise ValueError."""
    m = _finite(magnitudes)
    if dm < 0:
        raise ValueError(f"dm must be >= 0 (got {dm})")
    if not bin_width > 0:
        raise ValueError(f"bin width must be > 0 (got {bin_width})")
    nan = float("nan")
    if mc is None:
        if len(m) == 0:
            return BValue(b=nan, b_error=nan, a=nan, mc=nan, dm=float(dm), n=0,
                          note="no events: no b-value")
        mc = completeness_magnitude(m, dm if dm > 0 else bin_width)
    lower = mc - dm / 2.0
    tolerance = 1e-9 * max(1.0, abs(lower)) if dm > 0 else 0.0
    above = m[m >= lower - tolerance]
    n = len(above)
    if n < 2:
        return BValue(b=nan, b_error=nan, a=nan, mc=float(mc), dm=float(dm), n=n,
                      note=f"too few events at or above Mc = {mc:g} ({n}; a b-value "
                           f"needs 2 or more): no b-value")
    mean = float(np.mean(above))
    if not mean > lower:
        return BValue(b=nan, b_error=nan, a=nan, mc=float(mc), dm=float(dm), n=n,
                      note=f"every event sits at Mc = {mc:g}: no b-value")
    b = LOG10_E / (mean - lower)
    b_error = 2.3 * b * b * float(np.sqrt(np.sum((above - mean) ** 2) / (n * (n - 1))))
    return BValue(b=b, b_error=b_error, a=float(np.log10(n) + b * mc), mc=float(mc),
                  dm=float(dm), n=n)


def magnitude_from_energy(energy):
    """Magnitude of a released energy E [J] by fdem-cl's event rule (the engine's
    event_magnitude): M = 2/3 (log10 E - 4.8), the Gutenberg-Richter energy-magnitude
    relation log10 E = 1.5 M + 4.8; NaN where E <= 0 or is not finite."""
    e = np.asarray(energy, dtype=float)
    out = np.full(e.shape, np.nan)
    ok = np.isfinite(e) & (e > 0)
    out[ok] = (2.0 / 3.0) * (np.log10(e[ok]) - 4.8)
    return out


def magnitude_frequency(magnitudes, bin_width: float = 0.1):
    """(bin lower edges, events per bin, events at or above each edge) of the
    magnitudes, bins of `bin_width` with edges at its multiples."""
    m = _finite(magnitudes)
    if len(m) == 0:
        return np.zeros(0), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    index = np.floor(m / bin_width + 1e-9).astype(np.int64)
    lo, hi = int(index.min()), int(index.max())
    counts = np.bincount(index - lo, minlength=hi - lo + 1)
    edges = np.arange(lo, hi + 1) * bin_width
    cumulative = np.cumsum(counts[::-1])[::-1]
    return edges, counts, cumulative


# ---------------------------------------------------------------------------------------
# Fragment sizes

def _sizes_masses(sizes, masses=None):
    x = np.asarray(sizes, dtype=float).ravel()
    w = np.ones_like(x) if masses is None else np.asarray(masses, dtype=float).ravel()
    if w.shape != x.shape:
        raise ValueError(f"{len(x)} sizes but {len(w)} masses")
    keep = np.isfinite(x) & np.isfinite(w) & (x > 0) & (w > 0)
    x, w = x[keep], w[keep]
    if len(x) == 0:
        raise ValueError("no fragment with a size > 0 and a mass > 0")
    order = np.argsort(x, kind="stable")
    return x[order], w[order]


def passing(sizes, masses=None):
    """(sizes ascending, mass fraction of fragments of that size or finer). Without
    masses every fragment counts the same. Fragments of size or mass <= 0 or not finite
    are left out."""
    x, w = _sizes_masses(sizes, masses)
    return x, np.cumsum(w) / np.sum(w)


def _midpoints(sizes, masses=None):
    """Hazen plotting positions: (sizes ascending, (cumulative mass - m/2) / total)."""
    x, w = _sizes_masses(sizes, masses)
    return x, (np.cumsum(w) - 0.5 * w) / np.sum(w)


def percentile_size(sizes, masses, fraction: float) -> float:
    """Size with `fraction` of the mass at or below it (P50: 0.5, P80: 0.8): the smallest
    fragment size x with P(x) >= fraction (module docstring)."""
    if not 0.0 < fraction <= 1.0:
        raise ValueError(f"fraction must be in (0, 1] (got {fraction})")
    x, p = passing(sizes, masses)
    # Round-off of the cumulative sum (e.g. 0.1 + 0.2 + 0.2 < 0.5) must not skip a size.
    k = int(np.searchsorted(p, fraction - 1e-12, side="left"))
    return float(x[min(k, len(x) - 1)])


@dataclass
class RosinRammler:
    xc: float   # characteristic size: 63.2% passing
    n: float    # uniformity index
    rms: float  # root mean square miss of P over the fitted points

    def cdf(self, x):
        x = np.asarray(x, dtype=float)
        return 1.0 - np.exp(-(np.maximum(x, 0.0) / self.xc) ** self.n)

    def size(self, fraction: float) -> float:
        """Size at `fraction` passing on the fitted curve."""
        return float(self.xc * (-np.log(1.0 - fraction)) ** (1.0 / self.n))


@dataclass
class Swebrec:
    xmax: float  # largest size (P = 1)
    x50: float   # median size
    b: float     # curve undulation exponent
    rms: float   # root mean square miss of P over the fitted points
    bound: str = ""  # "lower"/"upper": the searched x_max is that end of its range

    def cdf(self, x):
        x = np.asarray(x, dtype=float)
        out = np.ones_like(x)
        inside = (x > 0) & (x < self.xmax)
        ratio = (np.log(self.xmax) - np.log(x[inside])) / np.log(self.xmax / self.x50)
        out[inside] = 1.0 / (1.0 + ratio ** self.b)
        out[x <= 0] = 0.0
        return out

    def size(self, fraction: float) -> float:
        """Size at `fraction` passing on the fitted curve."""
        ratio = (1.0 / fraction - 1.0) ** (1.0 / self.b)
        return float(self.xmax * np.exp(-np.log(self.xmax / self.x50) * ratio))


def _line(u, v):
    """Least-squares slope and intercept of v = slope u + intercept."""
    slope, intercept = np.polyfit(u, v, 1)
    return float(slope), float(intercept)


def rosin_rammler_fit(sizes, masses=None) -> RosinRammler:
    """Rosin-Rammler fit to the passing curve (module docstring)."""
    x, p = _midpoints(sizes, masses)
    if len(np.unique(x)) < 2:
        raise ValueError("a Rosin-Rammler fit needs fragments of two sizes at least")
    n, intercept = _line(np.log(x), np.log(-np.log1p(-p)))
    if not n > 0:
        raise ValueError(f"the passing curve does not rise with size (n = {n:g})")
    fit = RosinRammler(xc=float(np.exp(-intercept / n)), n=n, rms=0.0)
    fit.rms = float(np.sqrt(np.mean((fit.cdf(x) - p) ** 2)))
    return fit


def _swebrec_for(x, p, xmax):
    """Swebrec with this x_max, its x50 and b from the straight line; None if none."""
    # ln x_max - ln x, not ln(x_max / x): the ratio overflows for a size near the
    # smallest double, its logarithm does not.
    u = np.log(np.log(xmax) - np.log(x))
    v = np.log(1.0 / p - 1.0)
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(v))):
        return None
    slope, intercept = _line(u, v)
    if not slope > 0:
        return None
    x50 = xmax * np.exp(-np.exp(-intercept / slope))
    fit = Swebrec(xmax=float(xmax), x50=float(x50), b=slope, rms=0.0)
    fit.rms = float(np.sqrt(np.mean((fit.cdf(x) - p) ** 2)))
    return fit


def swebrec_fit(sizes, masses=None, xmax: Optional[float] = None) -> Swebrec:
    """Swebrec fit to the passing curve (module docstring); `xmax` fixes x_max (it must
    exceed the largest fragment), else it is searched up to ten times the largest."""
    x, p = _midpoints(sizes, masses)
    if len(np.unique(x)) < 2:
        raise ValueError("a Swebrec fit needs fragments of two sizes at least")
    largest = float(x[-1])
    if xmax is not None:
        if not xmax > largest:
            raise ValueError(f"xmax = {xmax:g} must exceed the largest fragment ({largest:g})")
        fit = _swebrec_for(x, p, xmax)
        if fit is None:
            raise ValueError("the passing curve does not rise with size")
        return fit

    def miss(t):  # t = ln ln(x_max / x_largest)
        fit = _swebrec_for(x, p, largest * np.exp(np.exp(t)))
        return (np.inf, None) if fit is None else (fit.rms, fit)

    grid = np.linspace(np.log(1e-4), np.log(np.log(10.0)), 121)
    misses = [miss(t)[0] for t in grid]
    k = int(np.argmin(misses))
    if not np.isfinite(misses[k]):
        raise ValueError("the passing curve does not rise with size")
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    c, d = hi - golden * (hi - lo), lo + golden * (hi - lo)
    fc, fd = miss(c)[0], miss(d)[0]
    for _ in range(60):
        if fc < fd:
            hi, d, fd = d, c, fc
            c = hi - golden * (hi - lo)
            fc = miss(c)[0]
        else:
            lo, c, fc = c, d, fd
            d = lo + golden * (hi - lo)
            fd = miss(d)[0]
    candidates = [(t,) + miss(t) for t in (lo, hi, 0.5 * (lo + hi), grid[k])]
    t_best, _, fit = min(candidates, key=lambda r: r[1])
    # On an end of the range the least miss may lie beyond it: say so (module docstring).
    span = grid[-1] - grid[0]
    if t_best - grid[0] < 1e-6 * span:
        fit.bound = "lower"
        warnings.warn(f"Swebrec fit: x_max = {fit.xmax:.4g} m sits on the lower bound of its "
                      f"search, the largest fragment ({largest:.4g} m): the least miss lies at "
                      f"or below the largest piece, where a Swebrec curve cannot go; x50 and "
                      f"b are those of that x_max", FitWarning, stacklevel=2)
    elif grid[-1] - t_best < 1e-6 * span:
        fit.bound = "upper"
        warnings.warn(f"Swebrec fit: x_max = {fit.xmax:.4g} m sits on the upper bound of its "
                      f"search, ten times the largest fragment ({largest:.4g} m): the passing "
                      f"curve has no Swebrec best inside the range; read x50 and b with care, "
                      f"or fix x_max (swebrec_fit(..., xmax=))", FitWarning, stacklevel=2)
    return fit


@dataclass
class SizeDistribution:
    n: int                    # fragments counted
    total_mass: float
    p50: float
    p80: float
    rosin_rammler: Optional[RosinRammler]
    swebrec: Optional[Swebrec]


def size_distribution(sizes, masses=None) -> SizeDistribution:
    """P50, P80 and both fits of a set of fragments (a fit is None where it cannot be
    made, e.g. with a single fragment size)."""
    x, w = _sizes_masses(sizes, masses)
    fits = []
    for fit in (rosin_rammler_fit, swebrec_fit):
        try:
            fits.append(fit(x, w))
        except (ValueError, np.linalg.LinAlgError):
            fits.append(None)
    return SizeDistribution(n=len(x), total_mass=float(np.sum(w)),
                            p50=percentile_size(x, w, 0.5), p80=percentile_size(x, w, 0.8),
                            rosin_rammler=fits[0], swebrec=fits[1])


def equivalent_diameter(areas: Sequence[float]) -> np.ndarray:
    """Diameter of the circle of the same area, sqrt(4 A / pi): the size of a 2D fragment."""
    return np.sqrt(4.0 * np.asarray(areas, dtype=float) / np.pi)
