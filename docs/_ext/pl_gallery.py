"""sphinx-gallery helpers for posturelab's examples.

posturelab's figures are pyplot-free (:func:`posturelab.viz.plots.new_figure` returns a
:class:`matplotlib.figure.Figure` that pyplot does not know), so sphinx-gallery's
matplotlib scraper cannot see them. :func:`figure_scraper` looks for ``Figure`` objects
in the example's global variables instead (directly, or inside a tuple, list or dict held
there), saves each one it has not saved before, and returns the reST for the images.

:func:`reset_argv` gives every example a scratch output directory outside the repository
as its first command-line argument, so the example's own ``save_figure`` writes its PNG
there and never into ``examples/``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

#: Where the examples write their own PNG files during a docs build (thrown away).
SCRATCH = Path(tempfile.mkdtemp(prefix="posturelab-gallery-"))


def _figures(value, depth: int = 0):
    from matplotlib.figure import Figure

    if isinstance(value, Figure):
        yield value
    elif depth == 0 and isinstance(value, (tuple, list)):
        for item in value:
            yield from _figures(item, depth + 1)
    elif depth == 0 and isinstance(value, dict):
        for item in value.values():
            yield from _figures(item, depth + 1)


def figure_scraper(block, block_vars, gallery_conf, **kwargs):
    """Save the example's new Figure objects to sphinx-gallery's image paths.

    Parameters
    ----------
    block : tuple
        The code block that was executed (label, content, line number).
    block_vars : dict
        sphinx-gallery's block variables; ``example_globals`` and
        ``image_path_iterator`` are used.
    gallery_conf : dict
        sphinx-gallery's configuration.

    Returns
    -------
    str
        The reST of the images (``sphinx_gallery.scrapers.figure_rst``), or "".
    """
    from sphinx_gallery.scrapers import figure_rst

    seen = block_vars.setdefault("posturelab_scraped_figures", set())
    new = []
    for value in list(block_vars["example_globals"].values()):
        for fig in _figures(value):
            if id(fig) not in seen and fig not in new:
                new.append(fig)
    paths = []
    for fig, path in zip(new, block_vars["image_path_iterator"]):
        fig.savefig(path, dpi=100)
        seen.add(id(fig))
        paths.append(path)
    # keep the figures alive until the example ends, so that ids are not reused
    block_vars.setdefault("posturelab_scraped_objects", []).extend(new)
    if not paths:
        return ""
    return figure_rst(paths, gallery_conf["src_dir"])


def reset_argv(gallery_conf, script_vars):
    """``sys.argv[1:]`` of every example: a scratch output directory. [path]"""
    out = SCRATCH / Path(script_vars["src_file"]).stem
    out.mkdir(parents=True, exist_ok=True)
    return [str(out)]
