"""A 3-D finite-element check of a design against the beam model (MODEL.md sections 2-4).

The beam model is Euler-Bernoulli theory with closed-form sections. Features that disturb
the strain field (pockets, flats and above all transverse holes) and the clamp are where it
stops being exact; this package measures by how much for one design.

How the check is made:

- The design's CAD solid (``designer.cad``) is written as STEP and read back by gmsh, which
  cuts it at the clamp face ``X = 0`` (the clamp block is not meshed: the clamp face is held
  fixed) and a few section sizes past the last gauge station, ``X = x_cut``. Every design is
  symmetric about the ``XZ`` plane and, under a load along ``Z``, antisymmetric about the
  ``XY`` plane, so only the quarter ``Y >= 0, Z >= 0`` is meshed, with ``u_y = 0`` on
  ``Y = 0`` and ``u_x = u_y = 0`` on ``Z = 0``.
  The STEP is built in a child process, so the CAD kernel's memory (about 0.5 GB) is gone
  before the mesh; the detail size fills a thin wall's thickness around the features' faces
  and grows from there to the section's size. Where gmsh's surface mesher leaves flat triangles
  on a floor radius's narrow faces and the 3-D mesh fails or holds tetrahedra of no volume,
  those faces are meshed again by gmsh's MeshAdapt (and the convergence mesh likewise).
- Linear elasticity with quadratic tetrahedra (scikit-fem's ``ElementTetP2``), assembled here
  in vectorised form, a chunk of elements at a time, and solved by conjugate gradients
  preconditioned with a two-level (quadratic / linear) cycle (the linear level solved exactly,
  or on a large mesh by one cycle of algebraic multigrid), in which the unknowns of the
  mesh's slivers (tetrahedra far flatter than a regular one, which gmsh leaves where a floor
  radius's narrow faces meet their neighbours) are also solved exactly; a thin wide plate, on
  which the linear level locks, by a sparse LU. Either solution must leave a small true residual
  ``||f - K u|| / ||f||``, checked here rather than taken from the solver.
- The load ``F_max`` at ``x_max`` enters at the cut face as its resultant (Saint-Venant): a
  uniform shear ``tau = -F/A`` and a bending stress ``sigma = M z / I`` with
  ``M = F (x_max - x_cut)``; ``A`` and ``I`` are integrated over the meshed cut face.
- The free-end deflection is the cut face's mean deflection ``w_c`` and rotation ``w'_c`` (least
  squares of ``u_x = -z w'``) carried to the free end with Timoshenko's theory over the plain rest:
  ``w(l) = w_c + w'_c (l - x_cut) + F a^3/(3EI) + F a^2/(2EI) (l - x_max) + F a/(kappa G A)``,
  ``a = x_max - x_cut``, with Cowper's shear coefficient ``kappa`` (``model.sections.shear_coefficient``).
- A gauge reads the mean of ``eps_xx`` over its grid's footprint (``grid_length x grid_width``
  centred on the station, on the gauge face: the pocket floor, or the beam's surface). Along
  each line of the grid that mean is exactly ``(u_x(end) - u_x(start)) / grid_length``; the
  lines are combined with Gauss-Legendre weights across the grid's width.
- The peak stress is the von Mises stress averaged at the mesh vertices, away from the
  clamp face, whose idealised full fixity is singular at its edges; the root stress stays
  the beam model's.
- Every run is repeated on a mesh one step coarser (solved in a child process at the same
  time as the requested one), and the change is reported as the
  mesh-convergence check: one verdict for the gauge strains and the deflection, one for the
  peak stress (measured at the same place on both meshes, and only where the mesh edges
  resolve a pocket's floor radius).

``verify_design(record, mesh, out_dir)`` returns a complete ``VerifyResult``; gmsh, scikit-fem,
cadquery and matplotlib are imported only inside the functions that need them.

Modules, one job each: ``geometry_mesh`` (the problem's numbers and the gmsh quarter model),
``solve`` (the elasticity solve), ``readout`` (strains, deflection and stresses from the
solution), ``compare`` (the runs set beside the beam model: ``verify_design``) and ``report``
(the verdict, its messages, verify.md, verify.json and the plot).
"""

from designer.checks.fea.compare import verify_design
from designer.checks.fea.geometry_mesh import CONVERGENCE_COARSENING, MESH_LEVELS
from designer.checks.fea.readout import StressPeak
from designer.checks.fea.report import (CONVERGED_DEFLECTION, CONVERGED_STRAIN, CONVERGED_STRESS,
                                        RESOLVED_RADIUS_SHARE, GaugeCheck, LimitCheck, MeshRun, VerifyResult,
                                        plot_surface_strain, report_markdown, write_outputs)

__all__ = ["CONVERGED_DEFLECTION", "CONVERGED_STRAIN", "CONVERGED_STRESS", "CONVERGENCE_COARSENING", "GaugeCheck",
           "LimitCheck", "MESH_LEVELS", "MeshRun", "RESOLVED_RADIUS_SHARE", "StressPeak", "VerifyResult",
           "plot_surface_strain", "report_markdown", "verify_design", "write_outputs"]
