"""The Python results against the Rust examples (bit for bit), SymPy's
bicycle, the paper's closed form for the wheel-axle, and Pinocchio's UR5.

The wheel-axle's reference is Wang & Pao's eq. 64, exact, which the Rust
tests hold it to as well: no SymPy data for the wheel-axle is committed
(the committed SymPy data is the bicycle's)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import REPO, rust_answers


def full_coordinates(model, rng, scale=1.0):
    return rng.uniform(-scale, scale, size=len(model.coordinate_names))


def test_wheel_axle_rhs_equals_rust_bit_for_bit(wheel_axle, rng):
    m = wheel_axle
    lines, xs, qs, vs, us = [], [], [], [], []
    for _ in range(40):
        q = full_coordinates(m, rng, 3.0)
        v = rng.uniform(-5, 5, size=len(m.speed_names))
        u = rng.uniform(-1, 1, size=len(m.input_names))
        lines.append({"q": dict(zip(m.coordinate_names, q)), "u": dict(zip(m.speed_names, v)),
                      "inputs": dict(zip(m.input_names, u)), "params": m.parameters})
        retained = [q[m.coordinate_names.index(r)] for r in m.info["retained"]]
        xs.append(np.concatenate([retained, v]))
        qs.append(q), vs.append(v), us.append(u)
    answers = rust_answers("wheel_axle", lines)
    for x, q, v, u, a in zip(xs, qs, vs, us, answers):
        expected = [a["qdot"][r] for r in m.info["retained"]] + [a["udot"][s] for s in m.speed_names]
        assert np.array_equal(m.rhs(x, u), np.array(expected))
        qdot = m.coordinate_rates(q, v, u)
        assert np.array_equal(qdot, np.array([a["qdot"][c] for c in m.coordinate_names]))


def test_wheel_axle_scene_and_energies_equal_rust(wheel_axle, rng):
    scene = wheel_axle.scene("contact_check")
    assert scene.name == "contact_check"
    q = full_coordinates(wheel_axle, rng, 2.0)
    v = rng.uniform(-3, 3, size=2)
    answers = rust_answers("wheel_axle", [{"q": dict(zip(scene.coordinate_names, q)),
                                            "u": dict(zip(scene.speed_names, v))}], scene="contact_check")
    a = answers[0]
    x = np.concatenate([[q[scene.coordinate_names.index(r)] for r in scene.info["retained"]], v])
    expected = [a["qdot"][r] for r in scene.info["retained"]] + [a["udot"][s] for s in scene.speed_names]
    assert np.array_equal(scene.rhs(x), np.array(expected))
    e = scene.energies(q, v)
    assert e["kinetic"] == a["energies"]["kinetic"]
    assert e["potential"] == a["energies"]["potential"]


def test_wheel_axle_matches_eq_64(wheel_axle, rng):
    """Wang & Pao's eq. 64 with the drive torque, solved by Cramer's rule."""
    p = wheel_axle.parameters
    a, l, M, r, g, alpha = p["a"], p["l"], p["mass"], p["rim"], p["g"], p["alpha"]
    x = np.column_stack([rng.uniform(-3, 3, 200), rng.uniform(-5, 5, 200), rng.uniform(-5, 5, 200)])
    tau = rng.uniform(-1, 1, (200, 1))
    d = wheel_axle.rhs(x, tau)
    s = g * np.sin(alpha) * np.cos(x[:, 0])
    a11, a12, b1 = 2 * a * (M + r), -l * (M + r), 2 * M * s + tau[:, 0] / a
    a21, a22, b2 = a * l * (M + r), -(M * l * l + r * l * l + r * a * a), M * l * s
    det = a11 * a22 - a12 * a21
    psi = (b1 * a22 - a12 * b2) / det
    phi = (a11 * b2 - b1 * a21) / det
    assert np.array_equal(d[:, 0], x[:, 1])
    np.testing.assert_allclose(d[:, 1], phi, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(d[:, 2], psi, rtol=1e-12, atol=1e-12)


def test_bicycle_against_sympy_reference(bicycle):
    """The rows SymPy mechanics' generated C computed
    (comparisons/sympy-whipple/build/check.json): state (q4, q5, q7, u4,
    u6, u7), steer torque, and the six rates."""
    data = json.loads((REPO / "comparisons/sympy-whipple/build/check.json").read_text())
    assert bicycle.info["retained"] == ["q4", "q5", "q7"]
    assert bicycle.speed_names == ["q4", "q6", "q7"]
    worst = 0.0
    for row in data["rows"]:
        state, torque = row["state"][:6], row["state"][6]
        got = bicycle.rhs(np.array(state), np.array([torque]))
        sympy = np.array(row["sympy"])
        worst = max(worst, float(np.max(np.abs(got - sympy) / np.maximum(np.abs(sympy), 1e-6))))
        # appell's answers committed beside SymPy's came from the generated
        # code of 2026-12-02, whose operations have been reordered since:
        # equal to round-off, not to the bit.
        np.testing.assert_allclose(got, np.array(row["appell"]), rtol=1e-13, atol=1e-13)
    # check.json reports 1.36e-12 between the two at these rows.
    assert worst < 1e-11, worst


def test_bicycle_rhs_and_jacobian_equal_rust(bicycle, rng):
    m = bicycle
    lines, xs, us = [], [], []
    for _ in range(10):
        q = full_coordinates(m, rng, 0.5)
        v = rng.uniform(-3, 3, size=3)
        u = rng.uniform(-1, 1, size=1)
        lines.append({"q": dict(zip(m.coordinate_names, q)), "u": dict(zip(m.speed_names, v)),
                      "inputs": dict(zip(m.input_names, u))})
        xs.append(np.concatenate([[q[m.coordinate_names.index(r)] for r in m.info["retained"]], v]))
        us.append(u)
    evals = rust_answers("whipple_bicycle", lines)
    jacs = rust_answers("whipple_bicycle", lines, action="jacobian")
    for line, x, u, e, j in zip(lines, xs, us, evals, jacs):
        expected = [e["qdot"][r] for r in m.info["retained"]] + [e["udot"][s] for s in m.speed_names]
        got = m.rhs(x, u)
        # The accelerations, and the rates of the coordinates whose rates are
        # speeds, to the bit; the pitch rate q5' (a dependent rate) the
        # command line takes from coordinate_rates, which the Python call
        # gives to the bit too.
        k = m.info["retained"].index("q5")
        keep = [i for i in range(len(got)) if i != k]
        assert np.array_equal(got[keep], np.array(expected)[keep])
        q = np.array([line["q"][c] for c in m.coordinate_names])
        qdot = m.coordinate_rates(q, x[3:], u)
        assert np.array_equal(qdot, np.array([e["qdot"][c] for c in m.coordinate_names]))
        np.testing.assert_allclose(got[k], expected[k], rtol=1e-12, atol=1e-14)
        A, B = m.linearize(x, u)
        # The command line's `jacobian` runs the rhs in dual numbers; the
        # generated Jacobian agrees with it to round-off, not to the bit.
        np.testing.assert_allclose(A, np.array(j["a"]), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(B, np.array(j["b"]), rtol=1e-12, atol=1e-12)
        xdot, A2, B2 = m.rhs_jacobian(x, u)
        assert np.array_equal(A2, A) and np.array_equal(B2, B)
        # the Jacobian's program computes the rates its own way
        np.testing.assert_allclose(xdot, got, rtol=1e-12, atol=1e-12)


def test_constraint_forces_equal_rust_bit_for_bit(wheel_axle, bicycle, rng):
    """The multipliers against the command line's `contacts` action."""
    for example, m, scale in (("wheel_axle", wheel_axle, 2.0), ("whipple_bicycle", bicycle, 0.5)):
        lines, args = [], []
        for _ in range(8):
            q = full_coordinates(m, rng, scale)
            v = rng.uniform(-3, 3, size=len(m.speed_names))
            u = rng.uniform(-1, 1, size=len(m.input_names))
            lines.append({"q": dict(zip(m.coordinate_names, q)), "u": dict(zip(m.speed_names, v)),
                          "inputs": dict(zip(m.input_names, u))})
            args.append((q, v, u))
        for (q, v, u), a in zip(args, rust_answers(example, lines, action="contacts")):
            lam, _ = m.constraint_forces(q, v, u)
            assert np.array_equal(lam, np.array(a["multipliers"])), example


def test_ur5_from_urdf_equals_rust_bit_for_bit(ur5, rng):
    lines, xs, us = [], [], []
    for _ in range(20):
        q = rng.uniform(-3, 3, 6)
        v = rng.uniform(-2, 2, 6)
        tau = rng.uniform(-10, 10, 6)
        lines.append({"q": dict(zip(ur5.coordinate_names, q)), "u": dict(zip(ur5.speed_names, v)),
                      "inputs": dict(zip(ur5.input_names, tau))})
        xs.append(ur5.reduced_state(q, v))
        us.append(tau)
    for x, u, a in zip(xs, us, rust_answers("ur5", lines)):
        expected = [a["qdot"][r] for r in ur5.info["retained"]] + [a["udot"][s] for s in ur5.speed_names]
        assert np.array_equal(ur5.rhs(x, u), np.array(expected))


def test_ur5_against_pinocchio(ur5):
    data = json.loads((REPO / "tests/reference/pinocchio/ur5.json").read_text())
    assert ur5.coordinate_names == data["joints"]
    states = data["states"]
    q = np.array([s["q"] for s in states])
    v = np.array([s["v"] for s in states])
    tau = np.array([s["tau"] for s in states])
    a = np.array([s["a"] for s in states])
    ddq = ur5.rhs(ur5.reduced_state(q, v), tau)[:, 5:]
    np.testing.assert_allclose(ddq, np.array([s["ddq"] for s in states]), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ur5.inverse_dynamics(q, v, a), np.array([s["rnea"] for s in states]),
                               rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(ur5.mass_matrix(q), np.array([s["mass_matrix"] for s in states]),
                               rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(ur5.bias_forces(q, v), np.array([s["nle"] for s in states]),
                               rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(ur5.gravity_forces(q), np.array([s["gravity_torque"] for s in states]),
                               rtol=1e-10, atol=1e-10)


def test_ur5_derivatives_against_pinocchio(ur5):
    """inverse_dynamics_derivatives against computeRNEADerivatives and
    forward_dynamics_derivatives against computeABADerivatives (the
    reference the Rust tests read), batched over the states and one by
    one."""
    data = json.loads((REPO / "tests/reference/pinocchio/derivatives/ur5.json").read_text())
    assert ur5.coordinate_names == data["joints"]
    states = data["states"]
    q, v, a, tau = (np.array([s[k] for s in states]) for k in ("q", "v", "a", "tau"))
    torques, dq, dv, m = ur5.inverse_dynamics_derivatives(q, v, a)
    accel, fq, fv, fu = ur5.forward_dynamics_derivatives(q, v, tau)
    pairs = ((dq, "dtau_dq"), (dv, "dtau_dv"), (m, "dtau_da"), (fq, "ddq_dq"), (fv, "ddq_dv"),
             (fu, "ddq_dtau"))
    for ours, key in pairs:
        theirs = np.array([s[key] for s in states])
        assert ours.shape == theirs.shape, key
        worst = np.max(np.abs(ours - theirs)) / (1.0 + np.max(np.abs(theirs)))
        assert worst < 1e-9, f"{key}: {worst:.2e}"
    np.testing.assert_allclose(torques, ur5.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-10)
    np.testing.assert_allclose(accel, ur5.rhs(ur5.reduced_state(q, v), tau)[:, 5:], rtol=1e-12, atol=1e-10)
    for k in (0, len(states) - 1):
        for batched, single in zip((accel, fq, fv, fu), ur5.forward_dynamics_derivatives(q[k], v[k], tau[k])):
            assert np.array_equal(batched[k], single)


def test_solo12_on_a_free_base_against_pinocchio(cache):
    """A floating-base robot from its URDF, compared with Pinocchio's
    reference state for state through the model's PinocchioMap: RNEA,
    CRBA, gravity, and ABA with the joints' torques (the reference's base
    wrench is not an input of the model; its ddq is checked through
    Pinocchio's M and nle instead)."""
    import appell

    data = json.loads((REPO / "tests/reference/pinocchio/robots/solo12.json").read_text())
    m = appell.from_urdf(REPO / data["urdf"], base="free", gravity=data["gravity"], progress=False)
    pin = m.pinocchio_map()
    names = [j["name"] for j in data["joints"]]
    assert names[0] == "root_joint" and pin.base == "root_joint"
    assert pin.joints == names[1:] and (pin.nq, pin.nv) == (data["nq"], data["nv"])
    assert pin.joints == m.pinocchio_map(joints=names[1:]).joints
    states = data["states"]
    q_pin, v_pin, a_pin, tau_pin = (np.array([s[k] for s in states]) for k in ("q", "v", "a", "tau"))
    q, v = pin.state_from(q_pin, v_pin)
    np.testing.assert_allclose(pin.q_to(q), q_pin, rtol=0, atol=1e-15)
    np.testing.assert_allclose(pin.v_to(q, v), v_pin, rtol=1e-14, atol=1e-13)

    def close(ours, key, tol=1e-10):
        theirs = np.array([s[key] for s in states])
        worst = np.max(np.abs(ours - theirs) / (1.0 + np.abs(theirs)))
        assert worst < tol, f"{key}: {worst:.2e}"

    v_dot = pin.a_from(q, v_pin, a_pin)
    close(pin.tau_to(q, m.inverse_dynamics(q, v, v_dot)), "rnea")
    close(pin.mass_to(q, m.mass_matrix(q)), "mass_matrix")
    close(pin.tau_to(q, m.gravity_forces(q)), "gravity_torque")
    np.testing.assert_allclose(pin.tau_from(q, pin.tau_to(q, v_dot)), v_dot, rtol=1e-12, atol=1e-12)
    # Forward dynamics with the joints' torques: M a + nle = [0, tau_joints].
    inputs = np.array([[s["tau"][6 + names[1:].index(i[len("tau_"):])] for i in m.input_names]
                       for s in states])
    accelerations = m.rhs(m.reduced_state(q, v), inputs)[:, len(m.info["retained"]):]
    a = pin.a_to(q, v, accelerations)
    mass, nle = (np.array([s[k] for s in states]) for k in ("mass_matrix", "nle"))
    joint_tau = tau_pin.copy()
    joint_tau[:, :6] = 0.0
    residual = np.einsum("kij,kj->ki", mass, a) + nle - joint_tau
    assert np.max(np.abs(residual)) / (1.0 + np.max(np.abs(joint_tau))) < 1e-10
    with pytest.raises(KeyError, match="no free or planar joint 'base'"):
        m.pinocchio_map(base="base")
    with pytest.raises(appell.ModelError, match="no map to Pinocchio's conventions"):
        m.pinocchio_map(joints=names[1:5])
    with pytest.raises(ValueError, match="expected"):
        pin.q_to(np.zeros(5))
    with pytest.raises(ValueError, match="have 20 and 3 rows"):
        pin.v_to(q, v[:3])
    with pytest.raises(ValueError, match=r"\(l, l\) or \(N, l, l\)"):
        pin.mass_to(q[0], np.zeros(18 * 18))
