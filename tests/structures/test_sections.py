"""Section properties and stresses against closed-form beam results (Roark, 8th ed.; Gere, Mechanics of Materials)."""
import math

import pytest

from structures.section_shapes.circular_tube import circular_tube
from structures.section_shapes.hollow_rectangle import hollow_rectangle
from structures.section_shapes.i_section import i_section
from structures.section_shapes.solid_rectangle import solid_rectangle
from structures.section_shapes.thin_walled_box import thin_walled_box
from structures.sections import section_stresses


def test_solid_rectangle_cantilever_root_stresses():
    # 0.1 m wide, 0.2 m high cantilever, tip load P = 1 kN along axis 3 at L = 2 m:
    # root bending moment about axis 2 is M = P L; sigma = M c / I = 6 M / (b h^2); tau = 1.5 P / A.
    b, h, p, length = 0.1, 0.2, 1000.0, 2.0
    s = solid_rectangle(b, h)
    out = section_stresses(s, [[0.0, 0.0, p]], [[0.0, p * length, 0.0]])
    assert out["bending"][0] == pytest.approx(6 * p * length / (b * h**2), rel=1e-12)
    assert out["transverse_shear"][0] == pytest.approx(1.5 * p / (b * h), rel=1e-12)
    # von Mises from the coincident peaks (conservative by construction)
    assert out["von_mises"][0] == pytest.approx(math.hypot(out["normal"][0], math.sqrt(3) * out["shear"][0]))


def test_square_torsion_matches_saint_venant():
    # Saint-Venant: tau_max = T / (0.208 a^3) for a square of side a (Roark Table 10.1);
    # the closed-form approximation used is within 1 % of it for a square.
    a, torque = 0.05, 100.0
    out = section_stresses(solid_rectangle(a, a), [[0, 0, 0]], [[torque, 0, 0]])
    assert out["torsion"][0] == pytest.approx(torque / (0.208 * a**3), rel=0.01)


def test_hollow_rectangle_is_outer_minus_inner():
    b, h, t = 0.3, 0.2, 0.01
    s = hollow_rectangle(b, h, t)
    assert s.area == pytest.approx(b * h - (b - 2 * t) * (h - 2 * t), rel=1e-12)
    assert s.second_moment_2 == pytest.approx((b * h**3 - (b - 2 * t) * (h - 2 * t) ** 3) / 12, rel=1e-12)
    # Bredt: tau = T / (2 A_m t), A_m = (b - t)(h - t)
    assert s.shear_per_torque == pytest.approx(1 / (2 * (b - t) * (h - t) * t), rel=1e-12)
    with pytest.raises(ValueError, match="wall"):
        hollow_rectangle(0.1, 0.1, 0.06)


def test_thin_walled_box_approaches_hollow_rectangle_for_thin_walls():
    # Thin-wall formulas converge to the exact ones as t / b -> 0 (error of order t / b).
    b, h, t = 1.0, 0.6, 1e-4
    thin = thin_walled_box(b - t, h - t, t, t)      # midline dimensions
    exact = hollow_rectangle(b, h, t)
    assert thin.second_moment_2 == pytest.approx(exact.second_moment_2, rel=1e-3)
    assert thin.second_moment_3 == pytest.approx(exact.second_moment_3, rel=1e-3)
    assert thin.shear_per_torque == pytest.approx(exact.shear_per_torque, rel=1e-3)


def test_circular_tube_limits():
    d = 0.1
    solid = circular_tube(d, d / 2)
    assert solid.second_moment_2 == pytest.approx(math.pi * d**4 / 64, rel=1e-12)
    assert solid.shear_per_force2 * solid.area == pytest.approx(4 / 3, rel=1e-12)     # 4V/(3A), solid shaft
    thin = circular_tube(d, 1e-5)
    assert thin.shear_per_force2 * thin.area == pytest.approx(2.0, rel=1e-3)         # 2V/A, thin tube
    # torsion T r / J with J = pi d^4 / 32
    assert solid.shear_per_torque == pytest.approx((d / 2) / (math.pi * d**4 / 32), rel=1e-12)
    # bending about both axes combines as the resultant for a round section
    out = section_stresses(solid, [[0, 0, 0]], [[0, 30.0, 40.0]])
    assert out["bending"][0] == pytest.approx(50.0 * (d / 2) / (math.pi * d**4 / 64), rel=1e-12)


def test_i_section_against_hand_calculation():
    # IPE 200-like: h 0.2, b 0.1, t_f 0.0085, t_w 0.0056 (m). Hand values:
    # A = 2 b t_f + (h - 2 t_f) t_w; I_strong = (b h^3 - (b - t_w)(h - 2 t_f)^3) / 12.
    h, b, tf, tw = 0.2, 0.1, 0.0085, 0.0056
    s = i_section(h, b, tf, tw)
    area = 2 * b * tf + (h - 2 * tf) * tw
    i_strong = (b * h**3 - (b - tw) * (h - 2 * tf) ** 3) / 12
    assert s.area == pytest.approx(area, rel=1e-12)
    assert s.second_moment_2 == pytest.approx(i_strong, rel=1e-12)
    # catalogue IPE 200: A = 28.5 cm^2 and I_y = 1943 cm^4 include four r = 12 mm root fillets,
    # each of area (1 - pi/4) r^2 at about h/2 - t_f - r/4 from the neutral axis.
    r = 0.012
    fillets = 4 * (1 - math.pi / 4) * r**2
    arm = h / 2 - tf - 0.2234 * r   # centroid of a fillet's spandrel: 0.2234 r from its corner
    assert s.area + fillets == pytest.approx(28.5e-4, rel=0.01)
    assert s.second_moment_2 + fillets * arm**2 == pytest.approx(1943e-8, rel=0.01)
    # web shear ~ V / (h_w t_w) within 20 % (the classical estimate of the mean web shear)
    assert s.shear_per_force3 == pytest.approx(1 / ((h - 2 * tf) * tw), rel=0.2)



def test_section_shapes_are_plug_ins_found_by_name():
    """Issue 21: one file per shape; the case schema's section kinds are the registry's."""
    from riskassess.cases.impact import SECTION_MODELS
    from structures.section_shapes import SHAPES

    assert set(SHAPES) == {"solid_rectangle", "hollow_rectangle", "thin_walled_box", "circular_tube", "i_section"}
    assert set(SECTION_MODELS) == set(SHAPES)
    for name, shape in SHAPES.items():
        assert list(SECTION_MODELS[name].model_fields) == ["kind", *shape.DIMENSIONS]


def test_an_unknown_section_shape_is_refused_listing_the_known_ones():
    """Issue 21: every plug-in family refuses an unknown name with the known ones (multibody/maths/plugins.py)."""
    from structures.section_shapes import SHAPES

    with pytest.raises(ValueError) as unknown:
        SHAPES["t_section"]
    assert str(unknown.value) == ("unknown section shape 't_section'; the known section shapes are: "
                                  "circular_tube, hollow_rectangle, i_section, solid_rectangle, thin_walled_box")
