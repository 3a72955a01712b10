"""Image scraper of the gallery: the PNG pictures an example writes.

The examples write their pictures to files (``Result.plot`` renders with
pyvista off-screen and closes its plotter), so neither the matplotlib nor the
pyvista scraper of sphinx-gallery sees them. After each code block this
scraper looks through the example's globals for :class:`pathlib.Path` values
that name an existing ``.png`` file it has not shown yet, and copies each into
the gallery.
"""
from __future__ import annotations

import shutil
from pathlib import Path

from sphinx_gallery.scrapers import figure_rst


def png_scraper(block, block_vars, gallery_conf) -> str:
    """Copy the new PNG files named in the example's globals into the gallery.

    Parameters
    ----------
    block : tuple
        The code block just executed (unused).
    block_vars : dict
        sphinx-gallery's state of the example: ``example_globals`` and
        ``image_path_iterator`` (where the next image goes).
    gallery_conf : dict
        The gallery configuration (``src_dir`` for the relative paths).

    Returns
    -------
    str
        The reST that shows the copied images (empty if there were none).
    """
    shown = block_vars.setdefault("_png_scraper_shown", set())
    found = []
    for value in list(block_vars["example_globals"].values()):
        if isinstance(value, Path) and value.suffix.lower() == ".png" and value.is_file():
            key = str(value.resolve())
            if key not in shown:
                shown.add(key)
                found.append(value)
    images = []
    for source, target in zip(found, block_vars["image_path_iterator"]):
        shutil.copyfile(source, target)
        images.append(target)
    return figure_rst(images, gallery_conf["src_dir"])
