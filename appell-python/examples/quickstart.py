"""appell from Python, start to finish: a model from text and a robot from
its URDF file, compiled once and cached, then evaluated, linearized and
simulated on NumPy arrays.

Run from the repository root (it reads examples/robots/ur5/ur5_robot.urdf):

    python appell-python/examples/quickstart.py
"""

import time

import numpy as np
from scipy.integrate import solve_ivp

import appell

# A pendulum hanging from a cart that slides freely (the README's model).
cart = appell.from_model(
    """
    coordinates(x, theta), speeds(x, theta), positive(m_cart, m_bob, l)
    point(C = O + x * N.x)
    point(P = C + l * sin(theta) * N.x - l * cos(theta) * N.y)
    particle(C, mass = m_cart), particle(P, mass = m_bob)
    inputs(push), force(C, push * N.x)
    gravity(-g * N.y)
    """,
    parameters={"m_cart": 2.0, "m_bob": 0.5, "l": 1.0, "g": 9.81},
    name="CartPendulum",
)
print("cart pendulum: state", cart.state_names, "inputs", cart.input_names)

# Upright, the pendulum is unstable: one eigenvalue of A is positive.
A, B = cart.linearize([np.pi, 0.0, 0.0], u=[0.0])
print("upright eigenvalues:", np.round(np.sort(np.linalg.eigvals(A).real), 4))

# Hanging, it swings: the native DOP853 and SciPy's agree.
t = np.linspace(0.0, 5.0, 51)
x0 = [0.5, 0.0, 0.0]
native = cart.simulate(x0, t, rtol=1e-10, atol=1e-12)
scipy = solve_ivp(cart.ode_function(), (0, 5), x0, t_eval=t, method="DOP853", rtol=1e-10, atol=1e-12)
print(f"theta(5 s) = {native[-1, 0]:.6f}; SciPy's DOP853 differs by {np.abs(scipy.y.T - native).max():.1e}")

# The UR5 read from its URDF file, fixed base, gravity along -z.
ur5 = appell.from_urdf("examples/robots/ur5/ur5_robot.urdf")
rng = np.random.default_rng(1)
q = rng.uniform(-np.pi, np.pi, (100_000, 6))
v = rng.uniform(-1, 1, (100_000, 6))
x = ur5.reduced_state(q, v)
start = time.perf_counter()
tau = ur5.gravity_forces(q)  # gravity compensation: holds each configuration still
rest = ur5.rhs(ur5.reduced_state(q, np.zeros_like(v)), tau)
elapsed = time.perf_counter() - start
print(f"UR5: gravity compensation at 100,000 configurations in {elapsed * 1e3:.1f} ms; "
      f"largest acceleration left {np.abs(rest[:, 5:]).max():.1e} rad/s^2")
M = ur5.mass_matrix(q[:3])
print("UR5 mass matrix at 3 configurations:", M.shape, "symmetric:", np.allclose(M, M.transpose(0, 2, 1)))
print("cache:", appell.cache_info())
