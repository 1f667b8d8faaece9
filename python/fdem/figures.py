"""Writing a matplotlib figure, for every plot of the package."""


def save(fig, path, error=OSError):
    """Writes `fig` to `path` (150 dpi, tight) and closes it; a failed write raises
    `error` naming the path (each front end has its own error type and exit code)."""
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=150, bbox_inches="tight")
    except OSError as exc:
        raise error(f"cannot write {path}: {exc.strerror or exc}")
    finally:
        plt.close(fig)
