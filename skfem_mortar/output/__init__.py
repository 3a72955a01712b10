"""The output layer: what a solve writes. The contact output of a pair (:mod:`.contact_output`),
atomic files (:mod:`.io`), checkpoints (:mod:`.checkpoint`), one run per output directory
(:mod:`.lock`, :mod:`.outdir`), pictures (:mod:`.plot`: the model figure; :mod:`.plot_lines`,
:mod:`.plot_geometry`, :mod:`.plot_draw`, :mod:`.plot_common`) and pyvista views (:mod:`.views`).
"""
