"""The shipped feature corrections against the project's own 3-D study (docs/model.md §7).

Reference: ``materials/corrections_study.csv``, made by ``python -m designer.checks.study``
(fpdesign verify's 3-D elasticity on a parametric grid), and fresh 3-D runs of a few of its
points."""

import math
from pathlib import Path

import pytest

from designer.checks import clamp_study, extra_length, fit_forms, fits, peak_places, study
from designer.checks.extra_length import prediction
from designer.model import corrections, domain

STUDY = Path(corrections.__file__).resolve().parents[2] / "materials" / "corrections_study.csv"


def _rows():
    # with each row's clamp_near, as fits.fit_table adds it
    return fits.with_nearness(study.read_csv(STUDY))


def _far_rows(rows):
    """The second feature of each row as a row of its own: its K_t at its own clamp ratio and
    nearness (the test's own reading of the columns, apart from ``fits.far_features``)."""
    return [{**r, "stress_ratio": r["stress_far"], "clamp_ratio": r["far_clamp_ratio"],
             corrections.CLAMP_NEAR: r["clamp_near_far"]}
            for r in rows if math.isfinite(r.get("stress_far", math.nan)) and "clamp_near_far" in r]


def _inside(fit, row) -> bool:
    if "clamp_ratio" in row and "length_ratio" in row:     # the near station's distance (a near-clamp fit's)
        row = {domain.NEAR_STATION: clamp_study.near_station(row), **row}
    return all(name in row and lo <= row[name] <= hi for name, (lo, hi) in fit.domain.items())


def _within_its_rule(quantity, fit, row) -> bool:
    """A fit that meets its rule predicts the row within FIT_ACCEPT, a rough one within its
    left-out error; a fit shipped shifted to its
    safe side (fits.SAFE_SIDE) misses on the unsafe side by at most FIT_ACCEPT, and on the safe
    side by at most its left-out error, its shift and FIT_ACCEPT."""
    error = fits.judged_error(quantity, row, prediction(fit, quantity, row))
    accept = fits.FIT_ACCEPT[quantity]
    if not fit.margin:
        # a fit that meets its rule, or a rough one (fits.FIT_CEILING) within its left-out error
        return abs(error) <= max(accept, fit.loo_max)
    shift = fit.margin if quantity in fits.KT else fit.margin * fits.error_weight(quantity, row)
    return -accept <= error <= fit.loo_max + shift + accept


def test_every_shipped_fit_reproduces_the_study_and_its_held_out_points():
    table = corrections.load()
    assert table.fits, "no corrections shipped"
    rows = _rows()
    for fam, quantities in table.fits.items():
        if fam == "plain":
            continue  # the clamp: test_the_clamp_fit_reproduces_the_series; the stiffness: test_model_stiffness
        mine = [r for r in rows if r["family"] == fam]
        for quantity, fit in quantities.items():
            if quantity == "near_clamp":
                continue  # test_the_near_clamp_fits_reproduce_the_study
            if fits.FACE in quantities and quantity in fits.KT:
                continue  # test_a_two_place_k_t_reads_each_place_and_every_peak
            column = fits.TARGETS[quantity]
            used = [r for r in mine if math.isfinite(r.get(column, math.nan)) and _inside(fit, r)]
            assert len(used) >= 2 * len(fit.coefficients), (fam, quantity)
            for r in used:
                # within the acceptance the fit was shipped under (its leave-one-out error)
                assert _within_its_rule(quantity, fit, r), (
                    fam, quantity, fits.judged_error(quantity, r, prediction(fit, quantity, r)), r)
            if fit.margin:
                assert quantity in fits.SAFE_SIDE and fit.loo_max <= fits.FIT_CEILING[quantity]
            else:
                assert fit.loo_max <= max(fits.FIT_ACCEPT[quantity], fits.FIT_CEILING[quantity])


def test_refitting_the_study_gives_the_shipped_table():
    from designer.checks import stiffness_study

    table, _ = fits.fit_table(_rows(), stiffness_rows=stiffness_study.read_csv(STUDY.parent / stiffness_study.TABLE))
    shipped = corrections.load()
    assert table.fits.keys() == shipped.fits.keys()
    for fam, quantities in shipped.fits.items():
        assert table.fits[fam].keys() == quantities.keys()
        for quantity, fit in quantities.items():
            again = table.fits[fam][quantity]
            if isinstance(fit, corrections.ClampFit):
                _same_clamp(again, fit)
                continue
            if isinstance(fit, corrections.StiffnessFit):
                for k in corrections.STIFFNESS_COEFFICIENTS:
                    assert getattr(again, k) == pytest.approx(getattr(fit, k), rel=1e-5), k
                continue
            if isinstance(fit, corrections.DecayFit):
                assert again.rate == pytest.approx(fit.rate, rel=1e-12)
                again, fit = again.poly, fit.poly
            elif isinstance(fit, corrections.EdgeFit):
                assert again.k0 == pytest.approx(fit.k0, rel=1e-12)
                again, fit = again.poly, fit.poly
            elif isinstance(fit, corrections.ClampShareFit):
                assert again.domain == fit.domain
                again, fit = again.poly, fit.poly
            assert again.exponents == fit.exponents
            # to the last digits a least-squares solve keeps across LAPACK builds: the clamp-share
            # fit's (rectangle pockets) moved by 7e-9 between two OpenBLAS builds
            assert again.coefficients == pytest.approx(fit.coefficients, rel=1e-7, abs=1e-12)


def _same_clamp(a, b) -> bool:
    for k in corrections.CLAMP_COEFFICIENTS:
        assert getattr(a, k) == pytest.approx(getattr(b, k), rel=1e-6), k
    return True


def test_the_clamp_fit_reproduces_the_series():
    # every plain-bar point of the study inside the fit's domain within 1 % (the 3-D acceptance
    # on gauge strain is 2 %), and the points left out of the fit within 2 %
    fit = corrections.clamp_fit(corrections.load())
    inside = [(w, u, c) for w, u, c in clamp_study.points(_rows()) if u >= fit.domain["station_width_ratio"][0]]
    assert len(inside) >= 25
    for w, u, c in inside:
        assert float(fit(w, u)) == pytest.approx(c, abs=0.01), (w, u)
    assert fit.loo_max <= 0.02
    # the clamp leaves round bars (w = 1) and points far from it alone, and its restraint of a
    # wide plate tends to the plane-strain limit nu^2 = 0.11 (nu = 0.33): never more
    assert float(fit(1.0, 0.3)) == 1.0 and float(fit(16.0, 5.0)) == pytest.approx(1.0, abs=1e-4)
    assert 1 - float(fit(16.0, fit.u0)) < 0.33 ** 2


@pytest.mark.slow
@pytest.mark.parametrize("index", [10, 28])
def test_fresh_3d_runs_reproduce_points_of_the_clamp_series(index):
    # a 4:1 bar 0.2 widths from the clamp, and a 16:1 plate 0.5 widths out
    case = study.clamp_cases()[index]
    rows = [r for r in _rows() if r["family"] == "rectangle-none"]
    row = min(rows, key=lambda r: abs(r["width_ratio"] - case.width / case.height)
              + abs(r["clamp_ratio"] * case.height - case.clamp_clearance) * 1e3)
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.strain_near / fresh.strain_far == pytest.approx(row["strain_near"] / row["strain_far"], rel=1e-4)


@pytest.mark.slow
def test_a_fresh_3d_run_reproduces_a_large_thin_tube_near_the_clamp():
    # the Ø60 mm tube of wall 0.05 D with its 3 mm grid 0.2 D from the clamp: the gauge grid is
    # shorter than the wall-sized elements, so the check refines the mesh round it
    # (checks.fea.geometry_mesh.GRID_ELEMENTS); the same figures again, and the two meshes of the
    # check agree within 1 % (without the refinement such grids moved 1-3 %)
    case = next(c for c in study.round_clamp_cases() if c.diameter == study.LARGE_CLAMP_DIAMETER
                and c.wall == pytest.approx(0.05 * c.diameter) and c.clamp_clearance == pytest.approx(0.2 * c.diameter))
    row = next(r for r in _rows() if r["family"] == "tube-none" and r["grid_ratio"] == pytest.approx(0.05)
               and r["wall_ratio"] == pytest.approx(0.05) and r["clamp_ratio"] == pytest.approx(0.2))
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.strain_near == pytest.approx(row["strain_near"], rel=1e-4)
    assert fresh.strain_far == pytest.approx(row["strain_far"], rel=1e-4)
    assert fresh.strain_mesh_change < 0.01


def _two_holes(gap: float) -> str:
    """The bench suite's 037-imperial design (a 4.19 x 13.96 mm 2024-T3 bar, three Ø6.03 mm holes)
    with its last two holes ``gap`` heights apart, edge to edge."""
    h, d, last = 13.96, 6.03, 58.48
    return ("name: two-holes\nload: {force: [2.14 N, 81 N], position: [66.5 mm, 115.9 mm]}\n"
            "electronics: {excitation: 3.3 V, gain: 500, noise: 0.19 mV}\ngauge: BF120-3AA\nbridge: half\n"
            f"limits: {{load_clearance: 0 mm}}\ndesign:\n  material: 2024-T3\n"
            f"  section: {{kind: rectangle, width: 4.19 mm, height: {h} mm}}\n"
            f"  stations: [31.0 mm, {last - d - gap * h:.2f} mm, {last} mm]\n  feature: {{kind: hole, diameter: {d} mm}}\n")


@pytest.mark.slow
def test_neighbouring_holes_read_as_isolated_ones_only_half_a_height_apart():
    # The hole fits are of isolated holes (the study's far hole 4 heights beyond the near one):
    # 0.15 h apart (the web the bench suite's 037 design had) the two holes' gauges read 6 % over
    # and 3 % under the corrected model in 3-D; 0.4 h apart within 1 %. The limit hole_gap_i
    # keeps designs 0.5 h apart (model.limits.HOLE_GAP).
    from designer.checks.fea import verify_design
    from designer.model.limits import HOLE_GAP
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    close = verify_design(evaluate_fixed(parse_spec_text(_two_holes(0.15), source="t")).record, mesh="normal")
    assert max(abs(r - 1) for r in close.ratios) > 0.03
    apart = evaluate_fixed(parse_spec_text(_two_holes(0.4), source="t"))
    assert all(abs(r - 1) <= 0.01 for r in verify_design(apart.record, mesh="normal").ratios)
    assert HOLE_GAP > 0.4
    gap = next(c for c in apart.record["constraints"] if c["name"] == "hole_gap_2")
    assert not gap["satisfied"] and gap["limit"] == pytest.approx(HOLE_GAP * 13.96e-3)


@pytest.mark.slow
def test_neighbouring_flats_read_as_isolated_ones_only_half_a_diameter_apart():
    # The pocket fits are of isolated pockets (the study's far pocket 4 sizes beyond the near
    # one). Two flats 3 mm deep on a Ø20 mm 6061-T6 bar (benchmarks/feature_gap_study.py, coarse
    # mesh): 0.05 D apart their gauges read 1.8 % and 2.2 % under the same pair 4 D apart, 0.5 D
    # apart within 0.35 %. The limit pocket_gap_i keeps designs 0.5 D apart (model.limits.POCKET_GAP).
    import dataclasses

    from designer.checks import study
    from designer.checks.fea import verify_design
    from designer.model.limits import POCKET_GAP
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    pair = study.Case("round-pocket", diameter=20e-3, depth=3e-3, clamp_clearance=20e-3)

    def judged(gap):
        result = evaluate_fixed(parse_spec_text(dataclasses.replace(pair, gap=gap).spec_text(), source="t"))
        limit = next(c for c in result.record["constraints"] if c["name"] == "pocket_gap_1")
        return verify_design(result.record, mesh="coarse").ratios, limit

    alone, _ = judged(study.FAR_GAP)
    close, close_limit = judged(0.05)
    apart, apart_limit = judged(0.5)
    assert all(c / a < 0.985 for c, a in zip(close, alone))
    assert all(abs(p / a - 1) < 0.005 for p, a in zip(apart, alone))
    assert POCKET_GAP >= 0.5
    assert close_limit["limit"] == pytest.approx(POCKET_GAP * 20e-3) and not close_limit["satisfied"]
    assert apart_limit["satisfied"]


@pytest.mark.slow
def test_neighbouring_slots_in_a_wide_bar_read_as_isolated_ones_a_quarter_width_apart():
    # Past a slot the load flows back from its side walls over about the bar's width: in an 8:1
    # bar (40 x 5 mm 6061-T6, the study's 5.5 mm slots 0.75 mm deep; benchmarks/feature_gap_study.py
    # --wide, coarse mesh) two slots half a height apart, which pocket_gap_i allows, read 2.8 %
    # under the same pair far apart; a quarter of the width apart (slot_width_gap_i) within 0.7 %.
    import dataclasses

    from designer.checks import study
    from designer.checks.fea import verify_design
    from designer.model.limits import POCKET_GAP, SLOT_WIDTH_GAP
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    b, h = 40e-3, 5e-3
    pair = study.Case("rectangle-pocket", width=b, height=h, depth=0.15 * h, clamp_clearance=b)

    def judged(gap):     # gap in m; Case.gap is in the bar's width here
        result = evaluate_fixed(parse_spec_text(dataclasses.replace(pair, gap=gap / b).spec_text(), source="t"))
        limits = {c["name"]: c for c in result.record["constraints"]}
        return verify_design(result.record, mesh="coarse").ratios, limits

    alone, _ = judged(study.FAR_GAP * b)
    close, close_limits = judged(POCKET_GAP * h)
    apart, apart_limits = judged(SLOT_WIDTH_GAP * b)
    assert all(c / a < 0.985 for c, a in zip(close, alone))
    assert all(abs(p / a - 1) < 0.007 for p, a in zip(apart, alone))
    assert close_limits["pocket_gap_1"]["satisfied"] and not close_limits["slot_width_gap_1"]["satisfied"]
    assert close_limits["slot_width_gap_1"]["limit"] == pytest.approx(SLOT_WIDTH_GAP * b)
    assert apart_limits["slot_width_gap_1"]["satisfied"]


def test_the_pocket_families_rows_are_of_the_normal_mesh():
    # the table says its mesh per row; the pocket families were run on the normal mesh, with
    # the floor radius resolved (the coarse-mesh rows of the first grid are gone)
    rows = [r for r in _rows() if r["family"].endswith("pocket")]
    assert rows and {r["mesh"] for r in rows} == {"normal"}
    assert all("notch_ratio" in r for r in rows)


# The Ø10 x 3 mm 7075-T6 tube with 2 mm deep flats 8.9 mm long (a BF120-3AA's backing and 1 mm
# margins) that the search chose for a generated imperial spec when tube flats were fitted from
# half a diameter: verify read its far gauge 0.978 and its deflection 0.981 of the model.
SHORT_TUBE_FLAT = """\
name: short-tube-flat
load: {force: [0.53 N, 8 N], position: [108 mm, 193 mm]}
electronics: {excitation: 3.3 V, gain: 1, noise_rti: 144 nV}
gauge: BF120-3AA
bridge: quarter
limits: {min_wall: 1 mm}
design:
  material: 7075-T6
  section: {kind: tube, diameter: 10 mm, wall: 3 mm}
  feature: {kind: pocket, depth: 2 mm}
  stations: [9.45 mm, 20.35 mm, 98.67 mm]
"""


def test_tube_flats_are_fitted_and_designed_from_one_diameter_long():
    """docs/model.md §7: the study's tube flats of half to one diameter (``MID_TUBE_GROUPS`` among
    them) read gauge strains that the shipped fit, carried below its domain, misses by more than
    twice the 2 % rule, while from one diameter up it meets the rule (above); so the fits, and the
    designs, start at ``length_ratio`` 1, and a fixed design below it is told so.
    Reference: the study's 3-D rows."""
    from designer.result.evaluation import evaluate, fixed_design
    from designer.spec.reader import parse_spec_text

    table = corrections.load()
    for quantity in ("strain", "extra_length", "stress"):
        assert table.fit("tube-pocket", quantity).domain["length_ratio"][0] >= 1.0, quantity
    fit = table.fit("tube-pocket", "strain")
    short = [r for r in _rows() if r["family"] == "tube-pocket" and 0.5 <= r["length_ratio"] < 1.0]
    assert len(short) >= 40
    misses = [abs(fits.judged_error("strain", r, fit(r))) for r in short]
    assert max(misses) > 2 * fits.FIT_ACCEPT["strain"]
    assert sum(m > fits.FIT_ACCEPT["strain"] for m in misses) >= 10
    spec = parse_spec_text(SHORT_TUBE_FLAT)
    ev = evaluate(fixed_design(spec).rounded(spec.cad), spec)
    assert "domain_length_ratio_min" in {v.name for v in ev.violations}


def _shipped_kt(table, fam, row) -> float:
    """The model's K_t of family ``fam`` at ``row``: its ``stress`` fit's, or the larger of a
    two-place K_t's fits (``_two_place_kt``)."""
    if table.fit(fam, fits.FACE) is not None:
        return _two_place_kt(table, fam, row)
    return prediction(table.fit(fam, "stress"), "stress", row)


def _inside_kt(table, fam, row) -> bool:
    """Whether ``row`` lies inside every K_t fit of ``fam`` (fits.KT)."""
    return all(_inside(f, row) for f in (table.fit(fam, q) for q in fits.KT) if f is not None)


def _two_place_kt(table, fam, row) -> float:
    """The model's K_t of a two-place family at ``row``: the larger of its fits (fits.KT; the
    model rounds the maximum off by at most 0.05 % above it)."""
    return max(prediction(table.fit(fam, q), q, row) for q in fits.KT)


def test_a_slots_k_t_of_two_places_reads_each_place_and_every_peak():
    """docs/model.md §7: a slot's K_t is the larger of two fits, its floor radius's (``stress``) and
    its rim's on the loaded outer face (fits.FACE, over the end mill's ``plan_notch``), each fitted
    to its own place's 3-D peak and both shifted together (fits.shifted_pair). Each reads its own
    place within its left-out error (under) and that plus the shift (over); their larger reads
    every study feature's 3-D peak, wherever it sits, at most FIT_ACCEPT under: the near features
    in its domain and the far ones. The pair's shift is less than that of one form fitted to the
    zone's peak (x1.066 against x1.101, benchmarks/two_place_kt.md). Reference: the study's 3-D
    rows and their places (checks.peak_places)."""
    table = corrections.load()
    two = [fam for fam, quantities in table.fits.items() if fits.FACE in quantities]
    assert two == ["rectangle-pocket"]
    one_form = {q: forms for q, forms in fit_forms.FIT_FORMS["rectangle-pocket"].items() if q != fits.FACE}
    one, _ = fits.fit_table(study.read_csv(STUDY), forms={"rectangle-pocket": one_form})
    assert table.fit("rectangle-pocket", "stress").margin < one.fit("rectangle-pocket", "stress").margin
    accept = fits.FIT_ACCEPT["stress"]
    for fam in two:
        mine = [r for r in _rows() if r["family"] == fam]
        kts = [table.fit(fam, q) for q in fits.KT]
        assert kts[0].margin == kts[1].margin
        for quantity, fit in zip(fits.KT, kts):
            used = [p for p in (fits.place_row(r, quantity) for r in mine) if p is not None and _inside(fit, p)]
            assert len(used) >= 2 * len(fit.coefficients), (fam, quantity)
            errors = [fits.judged_error("stress", r, prediction(fit, "stress", r)) for r in used]
            assert min(errors) >= -fit.loo_max and max(errors) <= fit.loo_max + fit.margin + accept, quantity
        inside = lambda r: all(_inside(f, r) for f in kts)  # noqa: E731 - a local test
        near = [r for r in mine if math.isfinite(r.get("stress_floor", math.nan)) and inside(r)]
        far = [r for r in _far_rows(mine) if inside(r)]
        assert len(near) >= 200 and len(far) >= 200
        for r in near + far:
            assert _two_place_kt(table, fam, r) >= (1 - accept) * r["stress_ratio"], r


def test_the_slot_s_floor_radius_k_t_is_chosen_by_its_left_out_error_on_the_unsafe_side():
    """docs/model.md §7, "Shifted fits judged on the side that sets the shift": a K_t ships shifted
    until no left-out point reads its 3-D peak more than FIT_ACCEPT under, so its shift is set by
    its misses on that side alone. Neuber's shape with the clamp term (fit_forms.SLOT_KT_CLAMP, 8
    terms) has the smaller left-out error on both sides (20.4 % against 24.0 % for a quadratic in
    notch_ratio, depth and the slot's share of the width), outside fits.PARSIMONY of which the rule
    judged on both sides passed the quadratic over; under, the quadratic misses by 11.3 % against
    12.5 %, and the pair of places shifted with it reads the study's slots less high: x1.066
    against x1.086, 25 of the 243 near features under 0.90 of the model in 3-D against 53, and the
    far ones 23 against 82. The shipped floor radius takes it. Reference: the study's 3-D rows and
    their places (checks.peak_places)."""
    fam = "rectangle-pocket"
    raw = study.read_csv(STUDY)
    quadratic = fit_forms.Terms(("notch_ratio", "depth_ratio", "pocket_width_ratio"),
                                tuple(fit_forms.monomials(3, 2)))
    rows = [r for r in (fits.place_row(r, "stress") for r in _rows() if r["family"] == fam) if r is not None]
    box = fit_forms.FIT_DOMAINS[fam]["stress"]
    data = [r for r in rows if fits._in_domain(r, box)]
    tried = {}
    for name, terms in (("clamp", fit_forms.SLOT_KT_CLAMP), ("quadratic", quadratic)):
        fit, left_out = fits.fit_terms(data, terms, lambda r: r["stress_ratio"],
                                       weight=lambda r: fits.error_weight("stress", r), box=box, quantity="stress")
        tried[name] = (fit, data, left_out)
    clamp, quad = tried["clamp"], tried["quadratic"]
    assert clamp[0].loo_max == pytest.approx(0.204, abs=0.001) and quad[0].loo_max == pytest.approx(0.240, abs=0.001)
    assert quad[0].loo_max > fits.PARSIMONY * clamp[0].loo_max      # out of the band judged on both sides
    assert fits.unsafe_error("stress", *clamp[1:]) == pytest.approx(0.125, abs=0.001)
    assert fits.unsafe_error("stress", *quad[1:]) == pytest.approx(0.113, abs=0.001)
    assert fits._parsimonious([clamp, quad], "stress")[0] is quad[0]
    # the pair shifted with each floor form, and how the study's features read against it
    readings = {}
    for name, terms in (("clamp", fit_forms.SLOT_KT_CLAMP), ("quadratic", quadratic)):
        forms = {**fit_forms.FIT_FORMS[fam], "stress": [terms]}
        table, _ = fits.fit_table(raw, forms={fam: forms})
        kts = [table.fit(fam, q) for q in fits.KT]
        inside = lambda r, kts=kts: all(_inside(f, r) for f in kts)  # noqa: E731 - a local test
        mine = [r for r in _rows() if r["family"] == fam]
        near = [r for r in mine if math.isfinite(r.get("stress_floor", math.nan)) and inside(r)]
        far = [r for r in _far_rows(mine) if inside(r)]
        low = [sum(r["stress_ratio"] < 0.90 * _two_place_kt(table, fam, r) for r in group) for group in (near, far)]
        readings[name] = (1 + kts[0].margin, len(near), *low)
    assert readings["clamp"] == pytest.approx((1.086, 243, 53, 82), abs=0.001)
    assert readings["quadratic"] == pytest.approx((1.066, 243, 25, 23), abs=0.001)
    shipped = corrections.load().fit(fam, "stress")
    assert shipped.variables == quadratic.variables and shipped.exponents == quadratic.exponents
    assert 1 + shipped.margin == pytest.approx(readings["quadratic"][0], rel=1e-9)


def test_the_extra_lengths_deflection_weight_is_the_beam_models_slope():
    # deflection_per_extra takes the deflection as linear in the extra length between Δ = 0 and
    # the fitted Δ; the beam model's own derivative at a study point agrees within 2 %
    case = next(c for c in study.cases(["tube-pocket"]))
    from designer import model
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    spec = parse_spec_text(case.spec_text(), source=case.family)
    design = evaluate_fixed(spec).evaluation.design
    g = design.geometry
    raw = model.analyse(g, design.material_params(spec), spec, table=corrections.Corrections({}))
    sp, E = raw.props, float(design.material.E)
    tip = lambda delta: float(model.tip_deflection(corrections.Widened(g, delta), sp, E,  # noqa: E731
                                                   spec.load.force_max, spec.load.position_max))
    extra = 0.45 * case.size          # about the study's figure for such a flat
    row = {"extra_length": extra / case.size, "deflection_ratio": tip(extra) / tip(0.0)}
    h = 1e-3 * case.size
    slope = (tip(extra + h) - tip(extra - h)) / (2 * h) * case.size / tip(extra)
    assert fits.deflection_per_extra(row) == pytest.approx(slope, rel=0.02)


def test_a_near_clamp_row_s_extra_length_is_its_two_flats_own_in_their_shares():
    # a round-flat row near the clamp holds one extra length for two flats, the far one with
    # none of the clamp's nearness: the fit is made to their own extra lengths weighted by their
    # shares of the deflection's slope (extra_length.features); the beam model with each flat
    # widened by its own gives the deflection of both widened by that weighted sum within 0.05 %
    from designer import model
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    fit = corrections.load().fit("round-pocket", "extra_length")
    assert corrections.CLAMP_NEAR in fit.variables
    rows = _rows()
    case, row = min(((c, _row_of(c, rows)) for c in study.group_cases(study.NEAR_CLAMP_GROUPS) if c.family == "round-pocket"),
                    key=lambda t: t[1]["clamp_ratio"])
    assert row["clamp_ratio"] < 0.2 and 0.1 < row["far_share"] < 0.3    # near the clamp; the far flat bends it too
    spec = parse_spec_text(case.spec_text(), source=case.family)
    design = evaluate_fixed(spec).evaluation.design
    g = design.geometry
    raw = model.analyse(g, design.material_params(spec), spec, table=corrections.Corrections({}))
    tip = lambda delta: float(model.tip_deflection(corrections.Widened(g, delta), raw.props,  # noqa: E731
                                                   float(design.material.E), spec.load.force_max,
                                                   spec.load.position_max))
    own = tuple(float(fit(p)) * g.size for p in corrections.feature_parameters(g))
    assert own[1] - own[0] > 0.03 * g.size      # the clamp's nearness makes them differ
    assert tip(own) == pytest.approx(tip(prediction(fit, "extra_length", row) * g.size), rel=5e-4)


def _group_rows(groups, rows):
    """The study's rows of the cases of pocket ``groups`` (``study.group_cases``), in the groups'
    order; a case the CAD could not build is not in the table."""
    out = []
    for case in study.group_cases(groups):
        try:
            out.append(_row_of(case, rows))
        except LookupError:
            continue
    return out


def _row_of(case, rows):
    from designer.errors import FpdError

    try:
        params = study.case_parameters(case)
    except FpdError as exc:     # no catalogue end mill cuts it: the study left it out
        raise LookupError(f"{case} is not in the table") from exc
    for r in rows:
        if r["family"] == case.family and all(
                r.get(k) == pytest.approx(v, rel=1e-5) for k, v in params.items() if k in r):
            return r
    raise LookupError(f"{case} is not in the table")


@pytest.mark.slow
@pytest.mark.parametrize("family, index", [("tube-pocket", 1), ("round-pocket", 1),
                                           ("rectangle-pocket", -32 - len(study.group_cases(study.NARROW_SLOT_GROUPS))),
                                           ("rectangle-pocket", -len(study.group_cases(study.NARROW_SLOT_GROUPS)))])
def test_fresh_3d_runs_reproduce_pocket_points_of_the_table_and_the_fits(family, index):
    # points of the study run again with the 3-D check on the study's own mesh: the same figures,
    # and any shipped fit of the family predicts them within its acceptance (the slots are the first
    # of the shallow slots with a sharp floor radius, study.SHALLOW_SHARP_SLOTS, and the first of the
    # narrower slots, study.NARROW_SLOTS, the last group: 3.6 mm wide, the one the K_t fit reads lowest)
    case = study.cases([family])[index]
    row = _row_of(case, _rows())
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.strain_far == pytest.approx(row["strain_far"], rel=1e-4)
    assert fresh.deflection_ratio == pytest.approx(row["deflection_ratio"], rel=1e-4)
    # as ``study --refresh`` solves it, which the extra length's fit weighs its errors by
    assert fresh.base_ratio == pytest.approx(row["base_ratio"], rel=1e-4)
    assert fresh.stress_ratio == pytest.approx(row["stress_ratio"], rel=1e-3)
    # the peaks on the floor radius and the outer face (checks.peak_places read the slots' rows
    # on the main mesh alone, the same mesh as the study's): the zone's peak is one of them here
    for column in peak_places.COLUMNS:
        if column in row:
            assert getattr(fresh, column) == pytest.approx(row[column], rel=1e-3), column
    if family == "rectangle-pocket":
        assert max(fresh.stress_floor, fresh.stress_face) == pytest.approx(fresh.stress_ratio, rel=1e-12)
    figures = {"strain": fresh.strain_far, "extra_length": fresh.extra_length, "stress": fresh.stress_ratio}
    table = corrections.load()
    for quantity, fit in table.fits.get(family, {}).items():
        if quantity not in figures:
            continue  # near_clamp: test_the_near_clamp_fits_reproduce_the_study; a two-place K_t: below
        values = {**fits.with_nearness([fresh.parameters])[0], "extra_length": fresh.extra_length,
                  "deflection_ratio": fresh.deflection_ratio, fits.TARGETS[quantity]: figures[quantity]}
        if quantity == "stress" and table.fit(family, fits.FACE) is not None:
            # a slot's K_t of two places: each fit reads its own place within its left-out error
            # (under) and that plus the shift (over), their larger the zone's peak at most
            # FIT_ACCEPT under (as test_a_slots_k_t_of_two_places_reads_each_place_and_every_peak)
            if _inside_kt(table, family, values):
                for q in fits.KT:
                    place, own = table.fit(family, q), {**values, "stress_ratio": getattr(fresh, fits.PLACE_COLUMNS[q])}
                    error = fits.judged_error("stress", own, prediction(place, "stress", own))
                    assert -place.loo_max <= error <= place.loo_max + place.margin + fits.FIT_ACCEPT["stress"], q
                assert _two_place_kt(table, family, values) >= (1 - fits.FIT_ACCEPT["stress"]) * fresh.stress_ratio
        elif _inside(fit, values):
            assert _within_its_rule(quantity, fit, values), quantity


@pytest.mark.slow
@pytest.mark.parametrize("index", [13, 29, 50, 84])
def test_fresh_3d_runs_reproduce_hole_points_of_the_table(index):
    # four hole cases of the study (one near Prototype B, the largest hole, a Ø0.6 h hole two
    # heights from the clamp in a 0.3:1 bar, where the fitted K_t turns the corner, and a Ø0.3 h
    # hole 0.25 h from the clamp in a 1.75:1 bar, whose gauge reads 5 % under the far one's)
    case = study.cases(["rectangle-hole"])[index]
    row = [r for r in _rows() if r["family"] == "rectangle-hole"][index]
    fresh = study.run_case(case, mesh=row["mesh"])
    assert fresh.parameters["hole_ratio"] == pytest.approx(row["hole_ratio"], rel=1e-5)
    assert fresh.parameters["clamp_ratio"] == pytest.approx(row["clamp_ratio"], rel=1e-5)
    assert fresh.strain_far == pytest.approx(row["strain_far"], rel=1e-4)
    assert fresh.strain_near == pytest.approx(row["strain_near"], rel=1e-4)
    assert fresh.deflection_ratio == pytest.approx(row["deflection_ratio"], rel=1e-4)
    assert fresh.stress_ratio == pytest.approx(row["stress_ratio"], rel=1e-3)


def test_the_near_clamp_fits_reproduce_the_study():
    # each family's near station over its far one (over the ClampFit's factor there) within the
    # fit's left-out error, which is within the gauge-strain acceptance of 2 % (a rough fit's
    # within FIT_CEILING: its error is room under the gauge-strain limit); round bars and tubes
    # read less near the clamp, down to about 0.93 with the gauge 0.05 diameters out
    table = corrections.load()
    clamp = corrections.clamp_fit(table)
    rows = _rows()
    for fam in ("round-none", "tube-none", "round-pocket", "tube-pocket", "rectangle-hole"):
        fit = table.fit(fam, "near_clamp")
        assert fit is not None and fit.loo_max <= fits.FIT_CEILING["strain"], fam
        assert corrections.strain_allowance(_plain_geometry(fam), table) >= fit.loo_max
        mine = [r for r in rows if r["family"] == fam and _inside(fit, r)]
        assert len(mine) >= 2 * len(fit.poly.coefficients), fam
        for r in mine:
            measured = fits.near_clamp_target(r, clamp)
            centre = clamp_study.near_station(r)      # the grid's centre, in sizes
            assert float(fit(r, centre)) == pytest.approx(measured, abs=fit.loo_max + 1e-9), (fam, r)
    nearest = min((r for r in rows if r["family"] == "round-none"), key=lambda r: r["clamp_ratio"])
    assert nearest["strain_near"] / nearest["strain_far"] < 0.95


def test_a_slot_near_the_clamp_sees_a_share_of_the_plain_bar_s_loss():
    # Each slot's near station over its far one: the plain bar's loss to the clamp (ClampFit) alone
    # misses the study by over 5 % (a deep slot's floor sees little of it), the shipped ClampShareFit
    # reproduces every row inside its domain within its left-out error (within the 2 % rule), and
    # the gauge-strain limit keeps at least that as room
    table = corrections.load()
    clamp = corrections.clamp_fit(table)
    fit = table.fit("rectangle-pocket", "near_clamp")
    assert isinstance(fit, corrections.ClampShareFit) and fit.loo_max <= fits.FIT_ACCEPT["strain"]
    assert corrections.strain_allowance(_plain_geometry("rectangle-pocket"), table) >= fit.loo_max
    rows = [r for r in fits.share_rows([r for r in _rows() if r["family"] == "rectangle-pocket"], clamp)
            if _inside(fit, r)]
    assert len(rows) >= 100
    assert max(abs(fits.near_clamp_target(r, clamp) - 1) for r in rows) > 0.05
    for r in rows:
        predicted = float(fit(r, r[corrections.CLAMP_DROP], r[corrections.STATION_NEAR]))
        assert predicted == pytest.approx(fits.near_clamp_target(r, clamp), abs=fit.loo_max + 1e-9), r


def test_slots_near_the_clamp_of_wide_bars_held_out_of_the_share_fit_read_it():
    # study.NEAR_CLAMP_WIDE_SLOTS (24 slots in bars 1.3-11 times as wide as high, their gauge a
    # quarter to two widths from the clamp face) were added after the share's form was chosen on
    # the others: a fit of that form to the other rows predicts them within 1.4 % (docs/model.md
    # section 7), inside the 2 % rule
    table = corrections.load()
    clamp = corrections.clamp_fit(table)
    shipped = table.fit("rectangle-pocket", "near_clamp")
    form = fit_forms.Terms(shipped.poly.variables, shipped.poly.exponents)
    rows = fits.share_rows([r for r in _rows() if r["family"] == "rectangle-pocket"], clamp)
    added = _group_rows(study.NEAR_CLAMP_WIDE_SLOT_GROUPS, rows)
    later = _group_rows(study.NARROW_SLOT_GROUPS, rows)    # run after the share's form was chosen
    held = [r for r in rows if any(r is a for a in added)]
    rest = [r for r in rows if not any(r is a for a in added + later)]
    assert len(held) == 24
    poly, _ = fits.fit_terms(rest, form, lambda r: fits.near_clamp_target(r, clamp) - 1)
    misses = [abs(1 + poly(r) - fits.near_clamp_target(r, clamp)) for r in held]
    assert max(misses) <= 0.0145, max(misses)


def test_a_thin_tube_near_the_clamp_follows_a_shells_edge_layer():
    # A thin tube held at its end bends its wall in a damped wave that decays over sqrt(R t)
    # (Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, ch. 15: the rate per unit
    # length is (3 (1 - nu^2))^(1/4) / sqrt(R t), i.e. k0 = 1.82 per diameter for nu = 0.33 with
    # b = k0 / sqrt(w (1 - w))). The shipped fit's k0 is within 20 % of that, and on the study's
    # Ø60 mm tube of wall 0.05 D its short grid a quarter of a diameter out reads the dip the 3-D
    # check measures (0.923 of the far station with the grid's centre 0.2575 D out) where the Ø20
    # series' long grid from the same backing end reads 0.97
    fit = corrections.load().fit("tube-none", "near_clamp")
    assert isinstance(fit, corrections.EdgeFit)
    nu = 0.33
    assert fit.k0 == pytest.approx((3 * (1 - nu ** 2)) ** 0.25 * 2 ** 0.5, rel=0.2)
    row = next(r for r in _rows() if r["family"] == "tube-none" and r["wall_ratio"] == pytest.approx(0.05)
               and r["grid_ratio"] == pytest.approx(0.05) and r["clamp_ratio"] == pytest.approx(0.2))
    measured = row["strain_near"] / row["strain_far"]
    assert measured < 0.93
    assert float(fit(row, clamp_study.near_station(row))) == pytest.approx(measured, abs=0.01)


def _plain_geometry(fam):
    from designer.model.sections import Geometry

    section, feature = fam.split("-")
    return Geometry(section, feature, (0.01, 0.05), 0.1, width=0.01, height=0.01, diameter=0.01, wall=0.002,
                    depth=0.001 if feature == "pocket" else 0.0, hole=0.003 if feature == "hole" else 0.0)


def test_the_study_s_extra_lengths_are_today_s_beam_model_s():
    """Each row's extra length is what remains of its 3-D deflection beyond today's beam model
    (``study --refresh``, as the study's command line solves it): a change of the beam model
    that the table was not refreshed for (its fits then correct a model that is gone) fails
    here. Reference: the rows' own 3-D deflections (deflection_ratio, base_ratio)."""
    from designer.checks import stiffness_study

    rows = study.read_csv(STUDY)
    stiffness = stiffness_study.fit(stiffness_study.read_csv(STUDY.parent / stiffness_study.TABLE))
    if stiffness.loo_max > fits.FIT_ACCEPT["extra_length"]:
        stiffness = None
    solved = study.refresh_extra_lengths([dict(r) for r in rows], stiffness)
    for old, new in zip(rows, solved):
        if math.isfinite(old.get("extra_length", math.nan)):
            assert new["extra_length"] == pytest.approx(old["extra_length"], abs=1e-5), old["family"]


def _mid_slots(rows):
    """(case, row) of the study's slots of one to two heights (``study.MID_SLOT_GROUPS``; one case
    the CAD could not build is not in the table)."""
    out = []
    for case in study.group_cases(study.MID_SLOT_GROUPS):
        try:
            out.append((case, _row_of(case, rows)))
        except LookupError:
            continue
    return out


def test_the_slot_strain_form_predicts_the_mid_slots_it_was_not_fitted_on():
    """docs/model.md §7: the slot strain fit's grid-gap form (``fit_forms.SLOT_GAP``), fitted on the
    study's slots before its slots of one to two heights were run (and the groups run after them),
    predicts those 46 within 3.5 %
    (measured 3.3 %); the quadratic in depth, length and side walls it replaced, fitted on the same
    rows, misses one of them by more than 5 % (measured 6.4 %: a slot 0.24 h deep, one height long,
    0.31 of the bar's width). Reference: the study's 3-D rows (materials/corrections_study.csv)."""
    rows = _rows()
    mid = [row for _, row in _mid_slots(rows)]
    assert len(mid) == 46
    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["strain"]
    later = mid + _group_rows(study.NEAR_CLAMP_WIDE_SLOT_GROUPS + study.SHALLOW_NARROW_SLOT_GROUPS
                              + study.SHALLOW_SHARP_SLOT_GROUPS, rows)
    earlier = [r for r in rows if r["family"] == "rectangle-pocket" and fits._in_domain(r, box)
               and not any(r is m for m in later)]
    held = [r for r in mid if fits._in_domain(r, box)]

    def worst(terms):
        fit, _ = fits.fit_terms(earlier, terms, lambda r: r["strain_far"])
        return max(abs(fit(r) - r["strain_far"]) for r in held)

    quadratic = fit_forms.Terms(("depth_ratio", "length_ratio", "side_wall_ratio"), tuple(fit_forms.monomials(3, 2)))
    assert worst(fit_forms.SLOT_GAP) <= 0.035
    assert worst(quadratic) > 0.05


def test_the_slot_strain_form_predicts_the_shallow_narrow_slots_it_was_not_fitted_on():
    """docs/model.md §7: 20 shallow slots a fifth to a third of a wide bar's width
    (``study.SHALLOW_NARROW_SLOTS``, where the optimiser puts slots in wide bars) were run after the
    other slots. The grid-gap form fitted without them (``fit_forms.SLOT_GAP``) reads them 2.4 % high on
    average and up to 6.5 %; with the side walls' share a quadratic in the depth
    (``fit_forms.SLOT_GAP_DEPTH``, shipped) within 2.1 %, 0.1 % on average. Reference: the study's 3-D
    rows (materials/corrections_study.csv)."""
    rows = _rows()
    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["strain"]
    slots = [r for r in rows if r["family"] == "rectangle-pocket" and fits._in_domain(r, box)]
    added = _group_rows(study.SHALLOW_NARROW_SLOT_GROUPS, rows)
    assert len(added) == 20
    later = _group_rows(study.SHALLOW_SHARP_SLOT_GROUPS, rows)     # (run after these)
    rest = [r for r in slots if not any(r is a for a in added + later)]

    def misses(terms):
        fit, _ = fits.fit_terms(rest, terms, lambda r: r["strain_far"])
        return [r["strain_far"] / fit(r) - 1 for r in added]

    before, now = misses(fit_forms.SLOT_GAP), misses(fit_forms.SLOT_GAP_DEPTH)
    assert min(before) < -0.06 and sum(before) / len(before) < -0.02
    assert max(abs(e) for e in now) <= 0.022 and abs(sum(now) / len(now)) <= 0.005
    shipped = corrections.load().fit("rectangle-pocket", "strain")
    assert shipped.exponents == fit_forms.SLOT_GAP_DEPTH.exponents


HOLDOUT = Path(__file__).resolve().parents[2] / "benchmarks" / "round_flat_holdout.py"


def test_the_round_flat_strain_form_predicts_long_grid_flats_it_was_not_fitted_on():
    """docs/model.md §7: 37 round flats 4-8 gauge grids long (under a grid shorter than the study's,
    on the study's beams and pockets; a third of them short flats near the clamp), held out of the
    fits (benchmarks/round_flat_holdout.csv, the 3-D check on the normal mesh:
    ``python benchmarks/round_flat_holdout.py``). The shipped strain fit, whose last term
    is the grid-gap decay over the flat's length, predicts them within 1.6 % (measured 1.53 %, one
    flat over 1.2 %; 1.49 % fitted without the study's flats with wide wire channels); the form
    before it, a fast decay exp(-27 g) in that term's place, fitted on the same study rows, missed
    shallow flats of 0.4-0.5 D by more than 1.7 % (measured 2.18 %)."""
    import importlib.util

    loader = importlib.util.spec_from_file_location("round_flat_holdout", HOLDOUT)
    holdout = importlib.util.module_from_spec(loader)
    loader.loader.exec_module(holdout)
    held = fits.with_nearness(study.read_csv(HOLDOUT.with_suffix(".csv")))
    cases = holdout.cases()
    assert len(held) == len(cases) == 37
    for row, case in zip(held, cases):    # the file's rows are the groups' cases, in order
        assert row["length_ratio"] == pytest.approx(study.case_parameters(case)["length_ratio"], rel=1e-5)
        assert 4.0 <= row["length_ratio"] / row["grid_ratio"] <= 8.0 + 1e-6
    assert max(abs(e) for _, e in holdout.errors(HOLDOUT.with_suffix(".csv"))) <= 0.016

    def fast(row):     # the former form's fast grid-gap decay
        return {**row, "gap_fast": math.exp(-27.0 * (row["length_ratio"] - row["grid_ratio"]) / 2)}

    box = fit_forms.FIT_DOMAINS["round-pocket"]["strain"]
    rows = [fast(r) for r in _rows() if r["family"] == "round-pocket" and fits._in_domain(r, box)]
    before = fit_forms.Terms(("depth_ratio", "gap_slow", "gap_fast"),
                        ((0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0), (1, 1, 0), (0, 0, 1)))
    former, _ = fits.fit_terms(rows, before, lambda r: r["strain_far"])
    assert max(abs(former(fast(r)) - r["strain_far"]) for r in held) > 0.017


@pytest.mark.slow
def test_a_deep_slot_one_height_long_narrow_in_a_wide_bar_reads_the_model_in_3d():
    """A slot 0.24 h deep, one height long and 0.31 of a bar twice as wide as high, outside the
    study's sample and inside every domain limit: the 3-D gauge strains within the slot strain
    fit's left-out error of the model (3-D/model 1.004 and 1.011 measured; 1.037 and 1.044 with the
    quadratic in depth, length and side walls shipped before the study's slots of one to two
    heights). Reference: a fresh 3-D run on the study's normal mesh."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    u = {"depth_ratio": 0.24, "length_ratio": 1.0, "pocket_width_ratio": 0.31, "notch_ratio": 0.5, "lp_grid": 3.0}
    case = study.pocket_case("rectangle-pocket", u, study.MID_SLOTS)
    with pytest.raises(LookupError):     # not a point of the study
        _row_of(case, _rows())
    ev = evaluate_fixed(parse_spec_text(case.spec_text())).evaluation
    assert not [v.name for v in ev.violations if v.name.startswith("domain_")]
    loo = corrections.load().fit("rectangle-pocket", "strain").loo_max
    for ratio in study.model_ratios(case, "normal"):
        assert abs(ratio - 1) <= loo, ratio


def test_a_slot_whose_side_walls_are_thinner_than_the_slot_k_t_fit_holds_for_is_kept_out():
    """docs/model.md §7: the slot's K_t is fitted, and designs kept, where the side walls are
    together at least 0.15 of the height. The study's slot 0.86 of a 6.4 mm bar's width (walls
    0.14 h together) reads a 3-D K_t of 1.37, 13 % above the fit of the others before its shift to
    the safe side (the shift that holds the others leaves it 3 % under); it and the study's four
    other slots of one to two heights with walls that thin are outside the fit's domain, and the
    beam evaluated reports ``domain_side_wall_ratio_min``. Reference: the study's 3-D rows."""
    from designer.result.pipeline import evaluate_fixed
    from designer.spec.reader import parse_spec_text

    table = corrections.load()
    for quantity in fits.KT:
        if table.fit("rectangle-pocket", quantity) is not None:
            assert table.fit("rectangle-pocket", quantity).domain["side_wall_ratio"][0] >= 0.15, quantity
    rows = _rows()
    thin = [(case, row) for case, row in _mid_slots(rows) if (case.width - case.pocket_width) / case.size < 0.15]
    assert len(thin) == 5 and not any(_inside_kt(table, "rectangle-pocket", row) for _, row in thin)
    # the one form fitted to the others (as it ships where the K_t is of one form), before its shift
    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["stress"]
    others = [r for r in rows if r["family"] == "rectangle-pocket" and fits._in_domain(r, box)]
    fit, _ = fits.fit_terms(others, fit_forms.SLOT_KT_DEEP, lambda r: r["stress_ratio"],
                            weight=lambda r: fits.error_weight("stress", r), box=box, quantity="stress")
    case, row = min(thin, key=lambda t: fits.judged_error("stress", t[1], fit(t[1])))
    assert row["pocket_width_ratio"] == pytest.approx(0.86, abs=0.005)
    assert fits.judged_error("stress", row, fit(row)) < -0.10   # the fitted K_t 12 % under the 3-D one
    ev = evaluate_fixed(parse_spec_text(case.spec_text())).evaluation
    assert "domain_side_wall_ratio_min" in [v.name for v in ev.violations]


def test_the_slot_k_t_fit_reads_shallow_slots_with_a_sharp_floor_radius_on_its_safe_side():
    """docs/model.md §7: 32 shallow slots with a micro end mill's sharp floor radius
    (``study.SHALLOW_SHARP_SLOTS``: sqrt(p/r) 1.8-3.4 at depths of 0.05-0.15 heights, where the
    other groups' least floor radius left few points) were run after the others. The shipped form
    fitted to the other rows reads their K_t 4 % under the 3-D one on average and up to 11 %
    under (before its shift); fitted with them, the one form read every one inside its domain at
    or above the 3-D K_t, and the shipped K_t of two places (shifted) reads each at most FIT_ACCEPT
    under it (two of 31 by 2.7 % and 4.4 %) and over it on average. Reference: the study's 3-D rows."""
    rows = _rows()
    added = _group_rows(study.SHALLOW_SHARP_SLOT_GROUPS, rows)
    assert len(added) == 32
    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["stress"]
    rest = [r for r in rows if r["family"] == "rectangle-pocket" and fits._in_domain(r, box)
            and math.isfinite(r.get("stress_ratio", math.nan)) and not any(r is a for a in added)]
    fit, _ = fits.fit_terms(rest, fit_forms.SLOT_KT_DEEP, lambda r: r["stress_ratio"],
                            weight=lambda r: fits.error_weight("stress", r), box=box, quantity="stress")
    before = [fits.judged_error("stress", r, fit(r)) for r in added]
    assert sum(before) / len(before) < -0.03 and min(before) < -0.10
    table = corrections.load()
    inside = [r for r in added if _inside_kt(table, "rectangle-pocket", r)]
    assert len(inside) >= 30
    after = [fits.judged_error("stress", r, _shipped_kt(table, "rectangle-pocket", r)) for r in inside]
    assert min(after) >= -fits.FIT_ACCEPT["stress"] and sum(after) / len(after) > 0.03


def test_slots_narrower_than_the_others_read_the_fits_made_without_them():
    """docs/model.md §7: 47 slots 2.7-5.5 mm wide (``study.NARROW_SLOTS``; the study's other slots
    are all 5.5 mm wide, so a slot's width over the bar's height and over its own length had not
    varied apart from its share of the bar's width) were run after the others. Fitted without them,
    the slot's gauge-strain form reads their strain factors within the 2 % rule (1.9 %), and the K_t
    form, shifted as it shipped then, reads them 9 % over their 3-D K_t on average, but one 6.4 % under,
    beyond the 5 % rule: a 3.6 mm slot in a 12.2 x 4.4 mm bar whose peak sits on the top face at its
    rim (benchmarks/slot_peak_places.md). Fitted with them, and shifted until it reads the study's
    far features as well (``fits.far_features``), the shipped K_t reads every one of them, near and
    far, at most 5 % under. Reference: the study's 3-D rows."""
    rows = _rows()
    narrow = _group_rows(study.NARROW_SLOT_GROUPS, rows)
    assert len(narrow) == 47
    rest = [r for r in rows if r["family"] == "rectangle-pocket" and not any(r is n for n in narrow)]
    table = corrections.load()
    before = {}
    for quantity in ("strain", "stress"):
        # the forms as they shipped then: the gauge strain's as it ships, K_t's of one form
        shipped = table.fit("rectangle-pocket", quantity) if quantity == "strain" else fit_forms.SLOT_KT_DEEP
        box, column = fit_forms.FIT_DOMAINS["rectangle-pocket"][quantity], fits.TARGETS[quantity]
        data = [r for r in rest if fits._in_domain(r, box) and math.isfinite(r.get(column, math.nan))]
        fit, left_out = fits.fit_terms(data, fit_forms.Terms(shipped.variables, shipped.exponents),
                                       lambda r, c=column: r[c], weight=lambda r, q=quantity: fits.error_weight(q, r),
                                       box=box, quantity=quantity)
        if quantity == "stress":
            fit = fits.shifted(fit, quantity, data, left_out)
        before[quantity] = [fits.judged_error(quantity, r, prediction(fit, quantity, r)) for r in narrow if _inside(fit, r)]
        assert len(before[quantity]) >= 40
    assert max(abs(e) for e in before["strain"]) <= fits.FIT_ACCEPT["strain"]
    assert sum(before["stress"]) / len(before["stress"]) > 0.05
    assert min(before["stress"]) < -fits.FIT_ACCEPT["stress"]
    far = _far_rows(narrow)
    after = [fits.judged_error("stress", r, _shipped_kt(table, "rectangle-pocket", r))
             for r in narrow + far if _inside_kt(table, "rectangle-pocket", r)]
    assert len(after) >= 80
    assert min(after) >= -fits.FIT_ACCEPT["stress"]


def _shifted_k_t(data, terms, box=()):
    """A K_t form fitted to ``data`` as the table ships a rough one: the fit, its left-out
    predictions, its shift to the safe side (fits.shifted) and each row's left-out over-read
    after that shift (predicted over 3-D, less one)."""
    fit, left_out = fits.fit_terms(data, terms, lambda r: r["stress_ratio"],
                                   weight=lambda r: fits.error_weight("stress", r), box=box, quantity="stress")
    margin = fits.shifted(fit, "stress", data, left_out).margin
    return fit, left_out, margin, [p * (1 + margin) / r["stress_ratio"] - 1 for p, r in zip(left_out, data)]


def test_the_slot_k_t_reads_deep_long_slots_as_evenly_as_the_rest():
    """docs/model.md §7: the slot K_t's term in notch_ratio x depth x length (fit_forms.SLOT_KT_DEEP).
    Left out one at a time and shifted to the safe side as the table ships them, the form without
    it reads the study's slots whose product is 1.5 or more (deep, long and sharp) 10 % over their
    3-D K_t on average, beyond the 3-D check's 10 % for a peak stress, while it reads the others
    6-9 % over; with it, those read 8 % over, and its largest left-out error is a sixth smaller
    (13.3 % against 16.0 %), which fits.PARSIMONY (1.15) takes. The study's rows as they were then
    (without the narrower slots run after). Reference: the study's 3-D rows."""
    rows = fits.with_nearness(_rows())
    later = _group_rows(study.NARROW_SLOT_GROUPS, rows)
    box = fit_forms.FIT_DOMAINS["rectangle-pocket"]["stress"]
    data = [r for r in rows if r["family"] == "rectangle-pocket" and fits._in_domain(r, box)
            and math.isfinite(r.get("stress_ratio", math.nan)) and not any(r is a for a in later)]
    deep = [r["notch_ratio"] * r["depth_ratio"] * r["length_ratio"] >= 1.5 for r in data]
    assert sum(deep) >= 25

    def over_read(terms):
        fit, _, _, over = _shifted_k_t(data, terms, box)
        return fit, sum(o for o, d in zip(over, deep) if d) / sum(deep)

    without, mean_without = over_read(fit_forms.SLOT_KT_CLAMP)
    with_term, mean_with = over_read(fit_forms.SLOT_KT_DEEP)
    assert mean_without > 0.095 and mean_with < 0.085
    assert with_term.loo_max * fits.PARSIMONY < without.loo_max


def test_the_round_flat_k_t_reads_flats_near_the_clamp_by_their_depth():
    """docs/model.md §7: the round flats' K_t lowers Neuber's slope near the clamp the more, the
    shallower the flat (fit_forms.FLAT_KT_CLAMP). Left out one at a time and shifted to the safe side
    as the table ships them, the clamp term alone reads the study's flats within 0.2 diameters of
    the clamp face and shallower than 0.2 D 10 % over their 3-D K_t on average (the deeper ones
    3 %), and every flat 6 % over (its shift x1.061); with the depth in the clamp term, 4 % and
    2.3 % (shift x1.024). Its left-out error is within fits.PARSIMONY of the clamp term's alone
    (10.8 % against 10.5 %), so a rough fit of a quantity with a safe side is chosen by its shift:
    the fewest terms (the rule for the others) would take the clamp term alone. The study's rows
    as they were then: without the flats with wide wire channels run after (next test).
    Reference: the study's 3-D rows."""
    rows = _rows()
    wide = _group_rows(study.CHANNEL_FLAT_GROUPS, rows)
    data = [r for r in rows if r["family"] == "round-pocket" and math.isfinite(r.get("stress_ratio", math.nan))
            and not any(r is w for w in wide)]
    shallow_near = [r["clamp_ratio"] < 0.2 and r["depth_ratio"] < 0.2 for r in data]
    assert sum(shallow_near) >= 10

    def over_read(terms):
        fit, left_out, margin, over = _shifted_k_t(data, terms)
        near = sum(o for o, s in zip(over, shallow_near) if s) / sum(shallow_near)
        return (fit, data, left_out), margin, near, sum(over) / len(over)

    alone, margin_alone, near_alone, mean_alone = over_read(fit_forms.neuber_with("clamp_near"))
    depth, margin_depth, near_depth, mean_depth = over_read(fit_forms.FLAT_KT_CLAMP)
    assert near_alone > 0.09 and mean_alone > 0.055 and margin_alone > 0.055
    assert near_depth < 0.05 and mean_depth < 0.03 and margin_depth < 0.03
    assert depth[0].loo_max <= fits.PARSIMONY * alone[0].loo_max
    assert fits._parsimonious([alone, depth], "stress")[0] is depth[0]
    assert fits._parsimonious([alone, depth], "strain")[0] is alone[0]


def test_the_round_flat_k_t_reads_a_flat_by_the_shoulder_its_wire_channel_leaves():
    """docs/model.md §7: the round flats' K_t reads Neuber's sqrt(t/r) at the highest shoulder the
    wire channel leaves at the flat's end wall (fit_forms.FLAT_KT_SHOULDER). 21 flats whose channel
    takes a quarter to three fifths of the chord at half the depth (``study.CHANNEL_FLATS``; the
    miniature bars' channels are half the flat's width and depth) were run after the others. Left
    out one at a time and shifted as shipped, FLAT_KT_CLAMP reads the study's flats that keep less
    than 0.85 of their shoulder 6.5 % over their 3-D K_t on average (up to 11 %), the others 2.3 %;
    with the shoulder, 2.8 % (up to 7 %), as the others (2.9 %), shifted no more (x1.030 both) and
    with a smaller left-out error (10.8 % against 11.3 %). Reference: the study's 3-D rows."""
    rows = _rows()
    assert len(_group_rows(study.CHANNEL_FLAT_GROUPS, rows)) == 21
    data = [r for r in rows
            if r["family"] == "round-pocket" and math.isfinite(r.get("stress_ratio", math.nan))]
    wide = [r["shoulder_ratio"] < 0.85 for r in data]
    assert sum(wide) >= 15

    def over_read(terms):
        fit, left_out, margin, over = _shifted_k_t(data, terms)
        inside = [o for o, w in zip(over, wide) if w]
        rest = [o for o, w in zip(over, wide) if not w]
        return (fit, data, left_out), margin, sum(inside) / len(inside), max(inside), sum(rest) / len(rest)

    clamp, margin_clamp, wide_clamp, top_clamp, rest_clamp = over_read(fit_forms.FLAT_KT_CLAMP)
    shoulder, margin_shoulder, wide_shoulder, top_shoulder, rest_shoulder = over_read(fit_forms.FLAT_KT_SHOULDER)
    assert wide_clamp > 0.06 and top_clamp > 0.10 and rest_clamp < 0.03
    assert wide_shoulder < 0.035 and top_shoulder < 0.08 and abs(wide_shoulder - rest_shoulder) < 0.005
    assert margin_shoulder <= margin_clamp and shoulder[0].loo_max < clamp[0].loo_max
    assert fits._parsimonious([clamp, shoulder], "stress")[0] is shoulder[0]
    shipped = corrections.load().fit("round-pocket", "stress")
    assert shipped.exponents == fit_forms.FLAT_KT_SHOULDER.exponents
    assert shipped.margin == pytest.approx(margin_shoulder, rel=1e-6)
    assert shipped.domain[corrections.SHOULDER] == (pytest.approx(min(r["shoulder_ratio"] for r in data)), 1.0)


@pytest.mark.parametrize("family", ["rectangle-pocket", "round-pocket", "tube-pocket"])
def test_the_sharpness_bound_is_the_studys_sharpest_pocket_at_each_depth(family):
    """docs/model.md §7: a pocket's K_t fit ships with the rising top of its study points in
    (depth_ratio, notch_ratio) (``notch_top``, the limit ``domain_notch_hull_max``): every point it
    was fitted on lies on or under it, each vertex is one of them, and at the shallowest depth it is
    well under the box's greatest notch_ratio (the study's sharp radii are on the deeper pockets).
    Reference: the study's 3-D rows."""
    fit = corrections.load().fit(family, "stress")
    rows = [r for r in _rows() if r["family"] == family and _inside(fit, r)
            and math.isfinite(r.get("stress_ratio", math.nan))]
    assert len(rows) >= 30 and len(fit.notch_top) >= 3
    points = {(r["depth_ratio"], r["notch_ratio"]) for r in rows}
    assert all(p in points for p in fit.notch_top)
    assert max(r["notch_ratio"] / domain.notch_top(r["depth_ratio"], fit.notch_top) for r in rows) <= 1 + 1e-9
    assert domain.notch_top(fit.domain["depth_ratio"][0], fit.notch_top) < 0.6 * fit.domain["notch_ratio"][1]


@pytest.mark.parametrize("family", ["rectangle-pocket", "round-pocket", "tube-pocket"])
def test_the_k_t_fit_predicts_the_far_features_it_was_not_fitted_on(family):
    """docs/model.md §4 and §7: the model takes K_t at every feature, each at its own nearness to
    the clamp, but the fits are made from the study's near features alone. Every study beam has a
    second feature further out (``stress_far``, at ``far_clamp_ratio``), which the 3-D check
    resolves as well (it refines every feature's floor radius): the shipped K_t, shifted to its
    safe side, reads each of them at most FIT_ACCEPT under the 3-D peak, as it does the features
    it was fitted on. Reference: the study's 3-D rows."""
    table = corrections.load()
    far = [r for r in _far_rows(r for r in _rows() if r["family"] == family) if _inside_kt(table, family, r)]
    assert len(far) >= 30
    errors = [fits.judged_error("stress", r, _shipped_kt(table, family, r)) for r in far]
    assert min(errors) >= -fits.FIT_ACCEPT["stress"]


@pytest.mark.slow
def test_the_middle_of_three_deep_slots_half_a_height_apart_loses_less_than_the_room_the_targets_keep():
    # The pocket fits are of isolated slots; with three stations the middle slot has a neighbour
    # on each side. An 8.5 mm square 7075-T6 bar with the deepest, shortest slots of the three-
    # station study (2.38 mm deep, 0.28 h; 8.93 mm long, as short as the gauge backing lets them
    # be; benchmarks/neighbour_study.py, its largest loss), F along -Z: half a height apart (the
    # closest pocket_gap_i allows) the middle gauge reads 1.18 % (normal mesh), 1.19 % (fine) under
    # the same bar's with its slots 4 heights apart, the outer ones 0.6-0.7 %: every gauge stays
    # inside the room u_eps the accuracy targets keep for the slots' strain fit (docs/model.md §4).
    import json

    from designer.checks.fea import verify_design
    from designer.model.limits import POCKET_GAP
    from designer.result.designfile import parse_design

    h, length = 8.5e-3, 8.93e-3

    def checked(gap):
        record = json.loads((Path(__file__).parent.parent / "data" / "biaxial_square_slots.json").read_text())
        d, spec = record["design"], record["spec"]
        d["feature"].update(depth=2.38e-3, length=length)
        first = 5e-3 + length / 2 + 1e-5
        d["stations"] = [first + i * (length + gap) for i in range(3)]
        end = d["stations"][-1] + length / 2
        d["length"], d["axes"], spec["axes"], spec["stations"] = end + 72e-3, 1, 1, 3
        spec["load"]["position"] = [end + 7e-3, end + 67e-3]
        return verify_design(record, mesh="coarse").ratios, parse_design(record).design.geometry

    (alone, _), (close, g) = checked(4 * h), checked(POCKET_GAP * h)
    assert POCKET_GAP == 0.5
    losses = [1 - c / a for c, a in zip(close, alone)]
    assert 0.009 < losses[1] < 0.016 and all(0.003 < x < losses[1] for x in (losses[0], losses[2])), losses
    room = corrections.strain_allowance(g, corrections.load())
    assert room > 0.03 and all(r > 1 - room / 3 for r in close), (close, room)
