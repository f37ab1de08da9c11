"""``fpdesign bench``: every search method over a suite of specs, against the best known design.

``suite`` makes the specs (the optimiser examples and generated ones), ``run`` runs every method
on each and establishes the best known design, ``summary`` tabulates the runs, ``figure`` draws
the chart of solve time against objective gap and ``files`` writes them all out.
"""

from types import ModuleType as _ModuleType

from designer.bench.figure import chart, chart_data
from designer.bench.files import runs_csv, specs_csv, stability_csv, write_bench
from designer.bench.run import (FAILURE_KINDS, REFERENCE_LEVELS, SOLVER_TOLERANCE, BenchResult, Run, Truth,
                                establish_truth, exact_gap, failures, gap, raw_gap, run_bench, run_method)
from designer.bench.suite import (CALIBRATION_LEVELS, DEFAULT_COUNT, DEFAULT_SEED, INFEASIBLE_KINDS, KIND_NOTES,
                                  KINDS, SECTION_KINDS, SuiteSpec, default_examples_folder, example_suite,
                                  generate_suite)
from designer.bench.summary import (SPREAD, construction_mismatches, failure_list, markdown, method_summary, os_cpu,
                                    pareto_front, stability_markdown, stability_rows, summary_tables,
                                    terminal_table)

__all__ = [name for name, value in globals().items()
           if not name.startswith("_") and not isinstance(value, _ModuleType)]
