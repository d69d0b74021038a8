"""Bad input raises chetaev's documented exceptions, with messages that say what was wrong;
a run that fails returns its partial motion instead."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import chetaev

t = me.dynamicsymbols._t


def test_the_exceptions_form_the_documented_hierarchy():
    assert issubclass(chetaev.ChetaevError, ValueError)
    assert issubclass(chetaev.ConversionError, chetaev.ChetaevError)
    assert issubclass(chetaev.SceneError, chetaev.ChetaevError)
    assert not issubclass(chetaev.SceneError, chetaev.ConversionError)


# --------------------------------------------------------------------------------------------
# Conversion of sympy expressions
# --------------------------------------------------------------------------------------------


def _convert(p, extra=0, **kwargs):
    return chetaev.Model.from_sympy(p["L"] + extra, p["q"], parameters=p["parameters"], **kwargs)


def test_a_symbol_without_a_value_is_refused_by_name(particle_sympy):
    kappa = sp.Symbol("kappa")
    x = particle_sympy["q"][0]
    with pytest.raises(chetaev.ConversionError, match=r"kappa.*parameters=\{kappa"):
        _convert(particle_sympy, kappa * x)


def test_a_dynamicsymbol_not_among_the_coordinates_is_refused_by_name(particle_sympy):
    z = me.dynamicsymbols("zeta")
    with pytest.raises(chetaev.ConversionError, match=r"zeta\(t\).*not among the coordinates"):
        _convert(particle_sympy, z**2)
    with pytest.raises(chetaev.ConversionError, match=r"zeta"):
        _convert(particle_sympy, z.diff(t) ** 2)


def test_a_second_derivative_in_the_lagrangian_is_refused_as_an_acceleration(particle_sympy):
    x = particle_sympy["q"][0]
    with pytest.raises(chetaev.ConversionError, match="acceleration"):
        _convert(particle_sympy, x * x.diff(t, 2))


@pytest.mark.parametrize("make", [
    lambda x: sp.floor(x),
    lambda x: sp.Piecewise((x, x > 0), (0, True)),
    lambda x: sp.sign(x),
    lambda x: sp.Max(x, 0),
], ids=["floor", "Piecewise", "sign", "Max"])
def test_a_function_chetaev_does_not_evaluate_is_refused_with_the_list_of_those_it_does(
    particle_sympy, make
):
    x = particle_sympy["q"][0]
    expr = make(x)
    with pytest.raises(chetaev.ConversionError) as info:
        _convert(particle_sympy, expr)
    msg = str(info.value)
    assert type(expr).__name__ in msg and "the Lagrangian" in msg and "atan2" in msg


def test_the_functions_chetaev_does_evaluate_agree_with_sympy(particle_sympy):
    x, y = particle_sympy["q"]
    xd = x.diff(t)
    extra = (sp.sqrt(x**2 + 1) + sp.sec(x) + sp.csc(x) + sp.cot(x) + sp.atan2(y, x)
             + sp.Abs(x) * xd + sp.exp(x) + sp.log(y) + sp.sinh(x) + sp.atanh(x / 3)
             + sp.acosh(y) + sp.cbrt(y))
    model = _convert(particle_sympy, extra)
    problem = chetaev.Problem(model, [0.4, 1.7], [1.0, 2.0])
    lag = particle_sympy["L"] + extra
    X, Y, U, V = sp.symbols("X Y U V")
    value = float(lag.subs({xd: U, y.diff(t): V}).subs({x: X, y: Y})
                  .subs({X: 0.4, Y: 1.7, U: 1.0, V: 2.0, **particle_sympy["parameters"]}))
    # one evaluation of a dozen O(1) terms: rounding only
    assert problem.equations_at(0.0, [0.4, 1.7], [1.0, 2.0])["lagrangian"] == pytest.approx(
        value, rel=1e-14)


def test_a_complex_number_is_refused(particle_sympy):
    with pytest.raises(chetaev.ConversionError):
        _convert(particle_sympy, sp.I * particle_sympy["q"][0])


def test_the_wrong_number_of_forces_is_refused_with_both_counts(particle_sympy):
    with pytest.raises(chetaev.ConversionError, match=r"1 generalised forces for 2 coordinates"):
        _convert(particle_sympy, forces=[0])


def test_a_holonomic_constraint_with_a_velocity_is_refused(particle_sympy):
    x = particle_sympy["q"][0]
    with pytest.raises(chetaev.ChetaevError, match="depends on the velocities"):
        _convert(particle_sympy, holonomic=[x + x.diff(t)])


def test_a_coordinate_that_is_not_a_dynamicsymbol_is_refused(particle_sympy):
    with pytest.raises(chetaev.ConversionError, match="dynamicsymbols"):
        chetaev.Model.from_sympy(particle_sympy["L"], [sp.Symbol("x")])


def test_a_parameter_that_is_not_a_number_is_refused(particle_sympy):
    m = particle_sympy["symbols"]["m"]
    with pytest.raises(chetaev.ConversionError, match="give it a number"):
        chetaev.Model.from_sympy(particle_sympy["L"], particle_sympy["q"],
                                 parameters={**particle_sympy["parameters"], m: "heavy"})


def test_loads_without_the_inertial_frame_are_refused(particle_sympy):
    N = me.ReferenceFrame("N")
    P = me.Point("P")
    P.set_vel(N, 0)
    with pytest.raises(chetaev.ConversionError, match="frame=N"):
        _convert(particle_sympy, loads=[(P, N.x)])


def test_with_parameters_refuses_a_parameter_the_model_does_not_have(particle_model):
    with pytest.raises(chetaev.ChetaevError, match=r"nope.*'m', 'g', 'v0'"):
        particle_model.with_parameters({"nope": 1.0})


# --------------------------------------------------------------------------------------------
# The initial state
# --------------------------------------------------------------------------------------------


def test_an_initial_velocity_off_the_constraint_is_refused_with_its_residual(particle_model):
    with pytest.raises(chetaev.ChetaevError, match=r"violates velocity constraint 1.*f = 1"):
        chetaev.Problem(particle_model, [0.0, 5.0], [10.0, 1.0])  # f = 101 - 100 = 1


def test_an_initial_velocity_off_the_constraint_is_projected_when_asked(particle_model):
    p = chetaev.Problem(particle_model, [0.0, 5.0], [10.0, 1.0], project_velocity=True)
    # smallest change in the metric W = I: the direction is kept, the speed scaled to v0
    np.testing.assert_allclose(p.qd0, np.array([10.0, 1.0]) * 10 / np.hypot(10, 1), rtol=1e-14)


@pytest.mark.parametrize("q0,qd0,where", [
    ([float("nan"), 5.0], [10.0, 0.0], r"q0\[0\].*NaN"),
    ([0.0, float("inf")], [10.0, 0.0], r"q0\[1\]"),
    ([0.0, 5.0], [float("nan"), 0.0], r"qd0\[0\]|q̇0\[0\]"),
])
def test_a_non_finite_initial_value_is_refused_naming_its_component(particle_model, q0, qd0, where):
    with pytest.raises(chetaev.ChetaevError, match=where):
        chetaev.Problem(particle_model, q0, qd0)


def test_an_initial_state_of_the_wrong_length_is_refused(particle_model):
    with pytest.raises(chetaev.ChetaevError, match="q0 has 3 entries.*N = 2"):
        chetaev.Problem(particle_model, [0.0, 5.0, 1.0], [10.0, 0.0, 0.0])


def test_an_unknown_route_is_refused_with_the_choices(particle_model):
    with pytest.raises(chetaev.ChetaevError, match="'graph'.*'dual'"):
        chetaev.Problem(particle_model, [0.0, 5.0], [10.0, 0.0], route="fast")


# --------------------------------------------------------------------------------------------
# Options
# --------------------------------------------------------------------------------------------


def test_an_unknown_method_is_refused_with_the_list_of_methods(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="euler") as info:
        chetaev.solve(particle_problem, 1.0, method="euler")
    assert all(m in str(info.value) for m in chetaev.methods())


def test_an_unknown_event_direction_is_refused_when_the_event_is_made(particle_sympy):
    with pytest.raises(chetaev.ChetaevError, match="'down'.*'either', 'rising' or 'falling'"):
        chetaev.Event("impact", particle_sympy["q"][1], direction="down")


@pytest.mark.parametrize("kwargs,match", [
    (dict(record="all"), "unknown record level 'all'"),
    (dict(output="every"), "unknown output 'every'"),
    (dict(output=[0.5, 2.0]), "output time 2 lies outside"),
    (dict(atol=[1e-9] * 3), r"atol \(length\)"),
    (dict(atol="tight"), "atol must be"),
    (dict(rtol=1e-20), "rtol"),
    (dict(project="yes"), "project must be"),
    (dict(project=1e-20), "projection tol"),
    (dict(max_step=-1.0), "max_step"),
    (dict(max_steps=0), "max_steps"),
    (dict(event_samples=10**6), "event_samples"),
    (dict(sensitivities=["nope"]), '"nope"'),
    (dict(method="rk4", step=0.0), "step must be"),
], ids=lambda v: v if isinstance(v, str) else None)
def test_a_bad_option_is_refused_naming_it(particle_problem, kwargs, match):
    with pytest.raises(chetaev.ChetaevError, match=match):
        chetaev.solve(particle_problem, 1.0, **kwargs)


def test_a_non_finite_end_time_is_refused(particle_problem):
    with pytest.raises(chetaev.ChetaevError, match="t_end"):
        chetaev.solve(particle_problem, float("nan"))


def test_an_event_with_a_symbol_without_a_value_is_refused_by_name(particle_problem):
    event = chetaev.Event("e", sp.Symbol("kappa") * sp.Symbol("y"))
    with pytest.raises(chetaev.ConversionError, match="kappa"):
        chetaev.solve(particle_problem, 1.0, events=[event])


def test_an_event_string_that_is_not_an_expression_is_refused(particle_problem):
    with pytest.raises(chetaev.ConversionError, match=r"cannot read the expression 'y \+\* 2'"):
        chetaev.solve(particle_problem, 1.0, events=[chetaev.Event("e", "y +* 2")])


def test_two_seeds_of_the_same_name_are_refused(particle_problem, particle_sympy):
    g = particle_sympy["symbols"]["g"]
    with pytest.raises(chetaev.ChetaevError, match='two seeds are named "g"'):
        chetaev.solve(particle_problem, 1.0, sensitivities=[g, "g"])


# --------------------------------------------------------------------------------------------
# A failed run is no exception
# --------------------------------------------------------------------------------------------


def test_a_run_that_reaches_its_step_limit_returns_its_partial_motion(particle_problem):
    sol = chetaev.solve(particle_problem, 10.0, max_steps=3)
    assert sol.status == "failed"
    assert sol.success is False
    assert isinstance(sol.message, str) and "step limit of 3" in sol.message
    assert len(sol) >= 1
    assert sol.t[-1] < 10.0
    assert "failed" in repr(sol)
    # everything recorded has one row per point
    for series in (sol.q, sol.qd, sol.mu, sol.energy):
        assert len(series) == len(sol)


# --------------------------------------------------------------------------------------------


def test_chetaev_errors_survive_pickling():
    for cls in (chetaev.ChetaevError, chetaev.SceneError):
        error = pickle.loads(pickle.dumps(cls("boom")))
        assert type(error) is cls and str(error) == "boom"


def test_an_event_expression_that_is_not_an_expression_is_refused_as_a_conversion_error(
    particle_problem,
):
    with pytest.raises(chetaev.ConversionError):
        chetaev.solve(particle_problem, 1.0, events=[chetaev.Event("e", None)])


def test_the_advice_for_an_inconsistent_initial_velocity_names_project_velocity(particle_model):
    with pytest.raises(chetaev.ChetaevError) as info:
        chetaev.Problem(particle_model, [0.0, 5.0], [10.0, 1.0])
    assert "project_velocity=True" in str(info.value)
    assert "::" not in str(info.value)


def test_the_advice_for_a_step_limit_names_the_max_steps_argument(particle_problem):
    message = chetaev.solve(particle_problem, 10.0, max_steps=3).message
    assert "max_steps=" in message and "::" not in message


@pytest.mark.parametrize("case", ["unknown parameter seed", "velocity seed"])
def test_sensitivity_messages_name_the_python_spelling_not_the_rust_api(particle_problem, case):
    seed = "nope" if case == "unknown parameter seed" else chetaev.Seed.velocity(0)
    with pytest.raises(chetaev.ChetaevError) as info:
        chetaev.solve(particle_problem, 1.0, sensitivities=[seed])
    assert "::" not in str(info.value), str(info.value)


@pytest.mark.parametrize("case", ["conversion", "holonomic with a velocity"])
def test_the_first_constraint_is_constraint_1_in_every_message(particle_sympy, case):
    x, y = particle_sympy["q"]
    with pytest.raises(chetaev.ChetaevError) as info:
        if case == "conversion":
            _convert(particle_sympy, constraints=[x.diff(t) - sp.Symbol("kappa")])
        else:
            _convert(particle_sympy, holonomic=[x + x.diff(t)])
    assert "constraint 1" in str(info.value), str(info.value)


@pytest.mark.parametrize("kwargs", [dict(method="dop853", step=1e-3),
                                    dict(method="rk4", step=1e-2, rtol=1e-10)],
                         ids=["step with dop853", "rtol with rk4"])
def test_an_option_the_method_does_not_use_is_refused(particle_problem, kwargs):
    with pytest.raises(chetaev.ChetaevError):
        chetaev.solve(particle_problem, 1.0, **kwargs)


# --------------------------------------------------------------------------------------------
# Models from operations directly
# --------------------------------------------------------------------------------------------

# L = 0.5 * qd^2 (a free particle): operations qd, 2, qd^2, 0.5, 0.5 * qd^2
FREE = [("qd", [], 0.0), ("const", [], 2.0), ("pow", [0, 1], 0.0), ("const", [], 0.5),
        ("mul", [2, 3], 0.0)]


def test_a_model_from_operations_moves_as_its_lagrangian_says():
    model = chetaev.Model(1, FREE, 4)
    assert model.coordinates == ["q1"] and model.operations == 5 and model.symbols is None
    sol = chetaev.solve(chetaev.Problem(model, [0.0], [1.5]), 2.0, rtol=1e-12, atol=1e-12,
                        output="final")
    assert sol.q[-1, 0] == pytest.approx(3.0, abs=1e-12)  # uniform motion: exact to rounding


@pytest.mark.parametrize("ops,root,match", [
    ([("foo", [], 0.0)], 0, "unknown operation 'foo'"),
    ([("mul", [1, 1], 0.0), ("qd", [], 0.0)], 0, "does not come before it"),
    ([("qd", [], 0.0)], 3, "the Lagrangian is operation 3"),
    ([("qd", [], 5.0)], 0, "names velocity 5"),
    ([("param", [], 0.0)], 0, "names parameter 0"),
], ids=["unknown op", "forward reference", "root out of range", "velocity index",
        "parameter index"])
def test_a_model_from_bad_operations_is_refused_naming_the_operation(ops, root, match):
    with pytest.raises(chetaev.ChetaevError, match=match):
        chetaev.Model(1, ops, root)


def test_events_on_a_model_from_operations_are_refused_pointing_to_from_sympy():
    problem = chetaev.Problem(chetaev.Model(1, FREE, 4), [0.0], [1.0])
    with pytest.raises(chetaev.ConversionError, match="from_sympy"):
        chetaev.solve(problem, 1.0, events=[chetaev.Event("e", "q1 - 0.5")])


def test_an_initial_state_may_be_a_dict_of_coordinates_and_is_checked(particle_model, particle_sympy):
    x, y = particle_sympy["q"]
    by_symbol = chetaev.Problem(particle_model, q0={y: 5.0, x: 0.0}, qd0={x.diff(): 10.0, y.diff(): 0.0})
    by_name = chetaev.Problem(particle_model, q0={"x": 0.0, "y": 5.0}, qd0={"x": 10.0, "y": 0.0})
    assert list(by_symbol.q0) == list(by_name.q0) == [0.0, 5.0]
    assert list(by_symbol.qd0) == [10.0, 0.0]
    with pytest.raises(chetaev.ConversionError, match="no value for y"):
        chetaev.Problem(particle_model, q0={x: 0.0}, qd0=[10.0, 0.0])
    with pytest.raises(chetaev.ConversionError, match="not a coordinate"):
        chetaev.Problem(particle_model, q0={"z": 0.0, "x": 0.0, "y": 5.0}, qd0=[10.0, 0.0])
    with pytest.raises(chetaev.ChetaevError, match="sequence of numbers"):
        chetaev.Problem(particle_model, q0="05", qd0=[10.0, 0.0])


def test_a_constraint_or_event_may_be_written_as_an_equation(particle_sympy):
    x, y = particle_sympy["q"]
    g, v0 = sp.symbols("g v0")
    L = (x.diff() ** 2 + y.diff() ** 2) / 2 - g * y
    model = chetaev.Model.from_sympy(L, [x, y], constraints=[sp.Eq(x.diff() ** 2 + y.diff() ** 2, v0**2)],
                                     parameters={g: 10, v0: 10})
    problem = chetaev.Problem(model, q0=[0, 5], qd0=[10, 0])
    event = chetaev.Event("impact", sp.Eq(y, 0), direction="falling", terminal=True)
    sol = chetaev.solve(problem, 10, rtol=1e-12, atol=1e-12, events=[event])
    # T = (v0/g) arccosh(exp(g h0/v0²)), to the tolerance with room.
    assert abs(sol.events[0].t - np.arccosh(np.exp(0.5))) < 1e-10


def test_coordinates_of_another_time_symbol_are_refused_with_the_argument_to_give():
    t = sp.Symbol("t", real=True)
    x = sp.Function("x")(t)
    with pytest.raises(chetaev.ConversionError, match=r"from_sympy\(\.\.\., t=t\)"):
        chetaev.Model.from_sympy(x.diff(t) ** 2 / 2, [x])
    # Given as t=, it is the time.
    model = chetaev.Model.from_sympy(x.diff(t) ** 2 / 2 + t * x, [x], t=t)
    sol = chetaev.solve(chetaev.Problem(model, q0=[0], qd0=[0]), 1.0, rtol=1e-12, atol=1e-12)
    # L = ẋ²/2 + t x: ẍ = t, x(1) = 1/6.
    assert abs(sol.q[-1, 0] - 1 / 6) < 1e-11
