"""Cost guard, static part (tests/cost_guard.py): XLA's cost analysis of the lowered
TCA programs of the involute and spiral-bevel families and of the efficiency program,
against the recorded baseline -- the graph size, without compiling or timing anything
(the involute TCA program is part of the efficiency program).
The dynamic part (Newton iterations executed) sits beside the module fixtures that
already run those TCAs (tests/test_tca.py, test_edge_contact.py, test_vh_catt.py,
test_preset_bevel_tca.py), so that it compiles nothing of its own.

Planted regressions it catches: the edge candidates traced twice or their number
raised (the involute TCA's flops grow 6.4x from no edge search to the ten candidates),
a solve left out of ``vmap`` and unrolled, a second TCA traced inside the efficiency
program."""

import gearjax as gj

from cost_guard import check_cost, static_cost


def test_cost_of_the_lowered_spiral_bevel_tca():
    d = gj.load_design(gj.example_path("spiral_bevel_10x30_synthesised"))
    f = gj.tca_function(d)
    check_cost("lowered_tca_spiral_bevel", **static_cost(f, f.pair))


def test_cost_of_the_lowered_efficiency_program():
    """TCA (with the involute edge search), load sharing and friction of a spur pair in
    one program: it stands for the involute TCA program too (lowering costs ~5 s of
    tracing per program; the involute TCA's own work is guarded in test_tca.py)."""
    des = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(20, 40, 4.0, 20.0), 30.0)
    f = gj.efficiency_function(des)
    oil, surf = gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)
    check_cost("lowered_efficiency_spur",
               **static_cost(lambda p: f(p, 100.0, 1000.0, oil, surf), f.pair))
