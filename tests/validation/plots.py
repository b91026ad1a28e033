"""The plot every validation check writes (a report, not part of the check): the computed
quantity against the exact solution or the experimental data, as a PNG, by default in the
output directory given to the check (`--plot PATH` writes it elsewhere, `--plot ''` not at
all). matplotlib with its Agg backend (no display); without matplotlib the check runs as
before and prints that the plot was skipped."""
import os


def add_option(ap, name):
    """Adds --plot PATH to the check's parser `ap`; the default is `name` in the output
    directory (see path)."""
    ap.add_argument("--plot", default=None, metavar="PATH",
                    help="write the plot to this PNG (default: %s in the output directory; "
                         "'' for none)" % name)
    ap.set_defaults(plot_name=name)


def path(args, directory=None):
    """Where the plot goes: --plot, else plot_name in `directory` (default: args.outdir);
    None for --plot ''."""
    if args.plot is not None:
        return args.plot or None
    return os.path.join(args.outdir if directory is None else directory, args.plot_name)


def pyplot():
    """matplotlib.pyplot on the Agg backend, or None where matplotlib cannot be imported."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    return plt


def write(args, draw, failures=(), directory=None, dpi=150):
    """Writes the plot of a check: draw(plt) makes the figure and returns it; it is saved to
    path(args, directory) and closed, marked FAILED when the check has `failures`. Prints
    where it went, or that it was skipped (no matplotlib, or --plot ''). Returns the path
    written, or None."""
    out = path(args, directory)
    if out is None:
        print("plot skipped (--plot '')")
        return None
    plt = pyplot()
    if plt is None:
        print("plot skipped: matplotlib is not available (%s not written)" % out)
        return None
    fig = draw(plt)
    # With failures, a strip at the bottom for the mark.
    fig.tight_layout(rect=(0, 0.04 if failures else 0, 1, 1))
    if failures:
        fig.text(0.995, 0.005, "FAILED: %d problem%s (see the check's output)"
                 % (len(failures), "" if len(failures) == 1 else "s"),
                 ha="right", va="bottom", color="red", fontsize=9)
    fig.savefig(out, dpi=dpi)
    plt.close(fig)
    print("plot written to %s" % out)
    return out
