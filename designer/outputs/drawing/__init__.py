"""A dimensioned shop drawing and a rendered picture of a designed beam (matplotlib only).

``plot_drawing(beam)`` (``sheet``) draws an A3 sheet in first-angle projection: a side view
(``X``-``Z``) above a top view (``X``-``Y``) (``views``), an enlarged section through the first
station (``section``), callouts for every machined feature, notes and a title block, all with
the sheet's ``pen``. Long plain runs of the beam are shortened with break lines and a slender
section is drawn deeper than the length scale (the view says so); the dimensions, along the
beam all from the clamp face, give the true sizes. ``plot_model(meshes, beam)`` (``picture``)
renders the tessellated solid in orthographic projection: shaded triangles painted far to
near, and the solid's edges with hidden parts removed against a depth buffer. Both take
``ax=None`` and return the figure; neither touches pyplot or rcParams. ``figures`` turns a
figure into SVG or PNG bytes and files. The part drawn is ``designer.outputs.part.BeamCad``.
"""

from designer.outputs.drawing.figures import figure_bytes, save_figure
from designer.outputs.drawing.picture import plot_model
from designer.outputs.drawing.sheet import plot_drawing

__all__ = ["figure_bytes", "plot_drawing", "plot_model", "save_figure"]
