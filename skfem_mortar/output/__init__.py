"""The output layer: what a solve writes. The contact output of a pair (:mod:`.contact_output`),
atomic files (:mod:`.io`; 3D cells in VTK's node order: :mod:`.vtk_cells`), checkpoints
(:mod:`.checkpoint`), one run per output directory (:mod:`.lock`, :mod:`.outdir`), meshes read
from files (:mod:`.mesh_io`), pictures (:mod:`.plot`: the 2D model figure; :mod:`.plot_lines`,
:mod:`.plot_geometry`, :mod:`.plot_draw`, :mod:`.plot_common`; :mod:`.render3d`: 3D models by
pyvista) and pyvista views (:mod:`.views`).
"""
