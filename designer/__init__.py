"""fpdesign: design, calibrate and read force-and-position cantilever sensors.

The package follows the flow of the work: ``spec`` (input) -> ``model`` (physics) ->
``optimize`` (search) -> ``result`` (design.json) -> ``report``, ``cad`` and ``plots``
(outputs), with ``calibration`` for the built sensor.
"""

__version__ = "0.1.0"
