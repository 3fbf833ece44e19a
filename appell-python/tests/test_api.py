"""Batches, threads, argument forms, simulation, scenes, info."""

from __future__ import annotations

import numpy as np
import pytest

import appell


def test_batched_equals_looped(ur5, rng):
    q = rng.uniform(-3, 3, (300, 6))
    v = rng.uniform(-2, 2, (300, 6))
    tau = rng.uniform(-5, 5, (300, 6))
    x = ur5.reduced_state(q, v)
    assert x.shape == (300, 11)  # the shoulder pan is cyclic under gravity along z
    assert np.array_equal(x[7], ur5.reduced_state(q[7], v[7]))
    batch = ur5.rhs(x, tau)
    assert batch.shape == (300, 11)
    looped = np.array([ur5.rhs(x[k], tau[k]) for k in range(300)])
    assert np.array_equal(batch, looped)
    m = ur5.mass_matrix(q)
    assert m.shape == (300, 6, 6)
    assert np.array_equal(m, np.array([ur5.mass_matrix(q[k]) for k in range(300)]))
    g = ur5.gravity_forces(q)
    assert np.array_equal(g, np.array([ur5.gravity_forces(q[k]) for k in range(300)]))
    a = ur5.inverse_dynamics(q, v, batch[:, 5:])
    assert np.array_equal(a, np.array([ur5.inverse_dynamics(q[k], v[k], batch[k, 5:]) for k in range(300)]))
    np.testing.assert_allclose(a, tau, rtol=1e-9, atol=1e-9)  # rnea(aba(tau)) = tau
    A, B = ur5.linearize(x[:5], tau[:5])
    assert A.shape == (5, 11, 11) and B.shape == (5, 11, 6)
    A0, B0 = ur5.linearize(x[3], tau[3])
    assert np.array_equal(A[3], A0) and np.array_equal(B[3], B0)
    rates = ur5.coordinate_rates(q, v, tau)
    assert np.array_equal(rates, np.array([ur5.coordinate_rates(q[k], v[k], tau[k]) for k in range(300)]))
    e = ur5.energies(q[:20], v[:20], tau[:20])
    for k in (0, 19):
        one = ur5.energies(q[k], v[k], tau[k])
        assert all(e[name][k] == one[name] for name in one)


def test_batched_constraint_forces_equal_looped(bicycle, rng):
    q = rng.uniform(-0.5, 0.5, (12, len(bicycle.coordinate_names)))
    v = rng.uniform(-3, 3, (12, 3))
    tau = rng.uniform(-1, 1, (12, 1))
    lam, qdd = bicycle.constraint_forces(q, v, tau)
    assert lam.shape == (12, bicycle.info["constraints"])
    for k in (0, 5, 11):
        lam_k, qdd_k = bicycle.constraint_forces(q[k], v[k], tau[k])
        assert np.array_equal(lam[k], lam_k) and np.array_equal(qdd[k], qdd_k)


def test_threads_do_not_change_results(ur5, rng):
    x = rng.uniform(-2, 2, (1000, 11))
    tau = rng.uniform(-5, 5, 6)  # one row of inputs for every state
    before = appell.get_num_threads()
    try:
        appell.set_num_threads(1)
        one = ur5.rhs(x, tau)
        appell.set_num_threads(2)
        two = ur5.rhs(x, tau)
    finally:
        appell.set_num_threads(before)
    assert np.array_equal(one, two)
    with pytest.raises(ValueError):
        appell.set_num_threads(0)


def test_argument_forms(wheel_axle):
    m = wheel_axle
    x = np.array([0.3, 0.2, 1.0])
    ref = m.rhs(x, [0.4])
    assert np.array_equal(m.rhs([0.3, 0.2, 1.0], np.array([0.4])), ref)
    assert np.array_equal(m.rhs({"phi": 0.3, "phi_dot": 0.2, "psi1_dot": 1.0}, {"tau": 0.4}), ref)
    # float32, non-contiguous, Fortran order: converted
    wide = np.zeros((3, 2), order="F")
    wide[:, 0] = x
    assert np.array_equal(m.rhs(wide[:, 0], [0.4]), ref)
    assert np.array_equal(m.rhs(np.tile(x, (4, 1))[:, :], np.full((4, 1), 0.4))[2], ref)
    # parameters for one call, by dict or array
    p = m.parameters
    other = m.rhs(x, [0.4], params={"alpha": 0.0})
    assert other[2] != ref[2]
    assert m.parameters == p
    arr = [p[k] for k in m.parameter_names]
    arr[m.parameter_names.index("alpha")] = 0.0
    assert np.array_equal(m.rhs(x, [0.4], params=np.array(arr)), other)


def test_info(wheel_axle, bicycle):
    info = wheel_axle.info
    assert info["name"] == "WheelAxle"
    assert info["state"] == ["phi", "phi_dot", "psi1_dot"]
    assert info["cyclic"] == ["x1", "y1", "x2", "y2", "psi2"]
    assert info["scenes"] == ["coasting", "driven", "track", "contact_check"]
    assert info["rhs_ops"]["total"] > 0
    assert info["parameter_values"]["a"] == 0.3
    assert "psi1" in info["equations"]
    assert wheel_axle.scene("driven").info["inputs"] == ["tau"]
    assert bicycle.info["jacobian"] is not None and bicycle.has_jacobian
    with pytest.raises(KeyError, match="did you mean 'coasting'"):
        wheel_axle.scene("coastin")


def test_parameters_persist_and_are_checked(wheel_axle):
    m = wheel_axle
    before = m.parameters
    try:
        m.parameters = {"alpha": 0.1}
        assert m.parameters["alpha"] == 0.1
        with pytest.raises(appell.ModelError, match="positive"):
            m.parameters = {"a": -1.0}
        assert m.parameters["a"] == before["a"]
    finally:
        m.parameters = before


def test_simulate_methods_and_scipy(wheel_axle):
    from scipy.integrate import solve_ivp, odeint

    m = wheel_axle
    x0 = np.array([0.3, 0.1, 0.0])
    t = np.linspace(0.0, 2.0, 21)
    dop = m.simulate(x0, t, u=[0.5], rtol=1e-11, atol=1e-12)
    assert dop.shape == (21, 3)
    assert np.array_equal(dop[0], x0)
    radau = m.simulate(x0, t, u=[0.5], method="radau5", rtol=1e-10, atol=1e-12)
    rk4 = m.simulate(x0, t, u=[0.5], method="rk4", h_max=1e-3)
    np.testing.assert_allclose(radau, dop, atol=1e-7)
    np.testing.assert_allclose(rk4, dop, atol=1e-9)
    f = m.ode_function(u=[0.5])
    sol = solve_ivp(f, (0.0, 2.0), x0, t_eval=t, method="DOP853", rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(sol.y.T, dop, atol=1e-8)
    vec = solve_ivp(f, (0.0, 2.0), x0, t_eval=t, method="Radau", vectorized=True, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(vec.y.T, dop, atol=1e-6)
    g = m.ode_function(form="odeint")
    y = odeint(g, x0, t, args=({"tau": 0.5}, m.parameters), rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(y, dop, atol=1e-7)
    # a batch of initial states equals the single runs
    many = np.array([x0, x0 + 0.1, x0 - 0.2])
    batch = m.simulate(many, t, u=[0.5])
    assert batch.shape == (3, 21, 3)
    for k in range(3):
        assert np.array_equal(batch[k], m.simulate(many[k], t, u=[0.5]))


def test_simulate_event(wheel_axle):
    # psi1_dot grows from 0 under gravity; stop where it reaches 1.
    times, states, event = wheel_axle.simulate([0.3, 0.0, 0.0], np.linspace(0, 5, 51), u=[0.0],
                                               event=lambda t, x: x[2] - 1.0)
    assert event is not None
    t_event, x_event = event
    assert abs(x_event[2] - 1.0) < 1e-6
    assert len(times) == len(states) and times[-1] <= t_event


def test_simulate_with_a_feedback_law(wheel_axle):
    from scipy.integrate import odeint

    m = wheel_axle
    x0 = np.array([0.3, 0.1, 0.0])
    t = np.linspace(0.0, 2.0, 21)
    # A law that returns the held value gives the held run, to the bit.
    for method, extra in (("dop853", {}), ("radau5", {}), ("rk4", {"h_max": 1e-2})):
        held = m.simulate(x0, t, u=[0.5], method=method, **extra)
        law = m.simulate(x0, t, u=lambda t, x: np.array([0.5]), method=method, **extra)
        assert np.array_equal(law, held), method
    # A damping torque on psi1's rate, returned as a dict, against odeint
    # calling the same law.
    calls = []

    def damping(t, x):
        calls.append(t)
        return {"tau": -2.0 * x[2]}

    dop = m.simulate(x0, t, u=damping, rtol=1e-11, atol=1e-12)
    assert len(calls) > len(t)
    y = odeint(m.ode_function(form="odeint"), x0, t, args=(lambda x, t: [-2.0 * x[2]],),
               rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(dop, y, atol=1e-7)
    free = m.simulate(x0, t, u=[0.0], rtol=1e-11, atol=1e-12)
    assert abs(dop[-1, 2]) < abs(free[-1, 2])
    radau = m.simulate(x0, t, u=damping, method="radau5", rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(radau, dop, atol=1e-7)
    # A batch runs its rows one after another with the law.
    many = np.array([x0, x0 + 0.1])
    batch = m.simulate(many, t, u=damping)
    for k in range(2):
        assert np.array_equal(batch[k], m.simulate(many[k], t, u=damping))
    # With an event as well.
    times, states, event = m.simulate([0.3, 0.0, 0.0], np.linspace(0, 5, 51),
                                      u=lambda t, x: [0.1], event=lambda t, x: x[2] - 1.0)
    assert event is not None and abs(event[1][2] - 1.0) < 1e-6


def test_odeint_form_without_inputs_is_pydys(pendulum):
    from scipy.integrate import odeint

    m = pendulum
    assert m.input_names == []
    x0, t = np.array([0.4, 0.0]), np.linspace(0.0, 1.0, 11)
    # PyDy's generated rhs of a system without specifieds is f(x, t, p).
    y = odeint(m.ode_function(form="odeint"), x0, t, args=({"m": 1.0, "l": 0.5, "g": 9.81},),
               rtol=1e-11, atol=1e-12)
    np.testing.assert_allclose(y, m.simulate(x0, t, rtol=1e-11, atol=1e-12), atol=1e-8)
    longer = odeint(m.ode_function(form="odeint"), x0, t, args=({"m": 1.0, "l": 2.0, "g": 9.81},),
                    rtol=1e-11, atol=1e-12)
    assert abs(longer[-1, 0] - y[-1, 0]) > 1e-3


def test_constraint_forces_and_energies(wheel_axle, rng):
    m = wheel_axle
    q = rng.uniform(-1, 1, 7)
    v = rng.uniform(-1, 1, 2)
    lam, qdd = m.constraint_forces(q, v, [0.3])
    assert lam.shape == (m.info["constraints"],) and qdd.shape == (7,)
    x = np.array([q[m.coordinate_names.index("phi")], *v])
    xdot = m.rhs(x, [0.3])
    # the oracle's accelerations of the privileged speeds agree with the rhs
    np.testing.assert_allclose(qdd[[m.coordinate_names.index("phi"), m.coordinate_names.index("psi1")]],
                               xdot[1:], rtol=1e-10, atol=1e-10)
    e = m.energies(np.tile(q, (3, 1)), np.tile(v, (3, 1)), [0.3])
    assert e["kinetic"].shape == (3,) and np.all(e["kinetic"] > 0)
    M, f = m.mass_matrix_and_forcing(q, v, [0.3])
    np.testing.assert_allclose(np.linalg.solve(M, f), xdot[1:], rtol=1e-10)


def test_two_models_from_one_module_keep_their_own_parameters(wheel_axle):
    from conftest import rust_model

    attributes, defaults, name = rust_model("wheel_axle.rs")
    steep = appell.from_model(attributes, parameters={**defaults, "alpha": 0.5}, name=name)
    assert appell.cache_info()["hits"] >= 1  # the same module, already loaded
    assert steep.parameters["alpha"] == 0.5 and wheel_axle.parameters["alpha"] == 0.2
    x = [0.3, 0.0, 0.0]
    assert steep.rhs(x, [0.0])[2] > wheel_axle.rhs(x, [0.0])[2]


def test_foot_forces_of_a_scene(cache, rng):
    """A one-legged robot on a free base standing on a point foot: the
    scene's foot force is its rows' multipliers, by axis."""
    from conftest import REPO

    robot = appell.from_urdf(REPO / "tests/data/one_leg.urdf", base="free", progress=False,
                             extra="contact(foot, point, effect = stance)\n"
                                   "scene(standing, effects(gravity, actuation, stance))")
    upright = {c: 0.0 for c in robot.coordinate_names}
    upright.update(root_joint_qw=1.0, root_joint_z=0.45, knee=-0.5)
    assert robot.info["feet"] == [] and robot.foot_forces(upright, np.zeros(9)) == {}
    standing = robot.scene("standing")
    assert standing.info["feet"] == [{"link": "foot", "flat": False}]
    q = np.zeros((6, len(standing.coordinate_names)))
    q[:, standing.coordinate_names.index("root_joint_qw")] = 1.0
    q[:, standing.coordinate_names.index("root_joint_z")] = 0.45
    q[:, standing.coordinate_names.index("hip_pitch")] = rng.uniform(0.2, 0.4, 6)
    q[:, standing.coordinate_names.index("knee")] = rng.uniform(-0.8, -0.4, 6)
    v = rng.uniform(-0.5, 0.5, (6, len(standing.speed_names)))
    u = rng.uniform(-1.0, 1.0, (6, len(standing.input_names)))
    feet = standing.foot_forces(q, v, u)
    assert list(feet) == ["foot"] and feet["foot"]["moment"] is None
    force, position = feet["foot"]["force"], feet["foot"]["position"]
    assert force.shape == (6, 3) and position.shape == (6, 3)
    lam, _ = standing.constraint_forces(q, v, u)
    for k in range(6):
        # The foot's three rows are among the multipliers, to the bit.
        assert all(f in set(lam[k]) for f in force[k]), (force[k], lam[k])
        one = standing.foot_forces(q[k], v[k], u[k])["foot"]
        assert np.array_equal(one["force"], force[k]) and np.array_equal(one["position"], position[k])
    # The foot is below the hip: 0.45 - 0.05 - 0.2 (cos a + cos(a + b)) up.
    a = q[:, standing.coordinate_names.index("hip_pitch")]
    b = q[:, standing.coordinate_names.index("knee")]
    np.testing.assert_allclose(position[:, 2], 0.4 - 0.2 * (np.cos(a) + np.cos(a + b)), atol=1e-14)


def _rk4(model, x, u, h):
    k1 = model.rhs(x, u)
    k2 = model.rhs(x + 0.5 * h * k1, u, t=0.5 * h)
    k3 = model.rhs(x + 0.5 * h * k2, u, t=0.5 * h)
    k4 = model.rhs(x + h * k3, u, t=h)
    return x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def _semi_implicit_euler(model, x, u, h):
    r = len(model.info["retained"])
    speeds = x[r:] + h * model.rhs(x, u)[r:]
    at_new_speeds = np.concatenate([x[:r], speeds])
    return np.concatenate([x[:r] + h * model.rhs(at_new_speeds, u)[:r], speeds])


@pytest.mark.parametrize("method, step", [("rk4", _rk4), ("semi_implicit_euler", _semi_implicit_euler)])
def test_step_jacobian_is_the_step_and_its_derivatives(ur5, wheel_axle, method, step, rng):
    # The UR5 through its generated Jacobian (chained through the stages),
    # the wheel-axle as well or by dual numbers: either way x⁺ is the step
    # written here from rhs, A and B its central differences.
    for model in (ur5, wheel_axle):
        s, ni, h = len(model.state_names), len(model.input_names), 0.01
        x = rng.uniform(-1, 1, s)
        u = rng.uniform(-1, 1, ni)
        nxt, A, B = model.step_jacobian(x, u, h=h, method=method)
        assert A.shape == (s, s) and B.shape == (s, ni)
        np.testing.assert_allclose(nxt, step(model, x, u, h), rtol=1e-12, atol=1e-12)
        eps = 1e-6
        for j in range(s):
            d = np.zeros(s)
            d[j] = eps
            column = (step(model, x + d, u, h) - step(model, x - d, u, h)) / (2 * eps)
            np.testing.assert_allclose(A[:, j], column, rtol=1e-6, atol=1e-8)
        for j in range(ni):
            d = np.zeros(ni)
            d[j] = eps
            column = (step(model, x, u + d, h) - step(model, x, u - d, h)) / (2 * eps)
            np.testing.assert_allclose(B[:, j], column, rtol=1e-6, atol=1e-8)
        # Batched rows are the single calls.
        xs, us = rng.uniform(-1, 1, (4, s)), rng.uniform(-1, 1, (4, ni))
        batch = model.step_jacobian(xs, us, h=h, method=method)
        for k in (0, 3):
            for got, one in zip(batch, model.step_jacobian(xs[k], us[k], h=h, method=method)):
                assert np.array_equal(got[k], one)


def test_step_jacobian_without_inputs_and_bad_arguments(pendulum):
    x = np.array([0.4, -0.2])
    nxt, A, B = pendulum.step_jacobian(x, h=0.01, method="semi_implicit_euler")
    # ω⁺ = ω − h (g/l) sin θ, θ⁺ = θ + h ω⁺.
    dw = -0.01 * 9.81 / 0.5 * np.cos(0.4)
    np.testing.assert_allclose(A, [[1 + 0.01 * dw, 0.01], [dw, 1.0]], rtol=1e-12)
    assert B.shape == (2, 0)
    with pytest.raises(ValueError, match="semi_implicit_euler"):
        pendulum.step_jacobian(x, h=0.01, method="euler")
    with pytest.raises(appell.ModelError, match="`h` has a non-finite entry"):
        pendulum.step_jacobian(x, h=float("nan"))
