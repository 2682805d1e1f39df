"""Small numba kernels for rigid-body kinematics (quaternions are w, x, y, z).

Conventions (Chrono's): the angular velocity of a body is stored in its own
frame, and a quaternion ``q`` maps body coordinates to world coordinates,
``x_world = R(q) x_body``.
"""
import math

import numpy as np
from numba import njit


@njit(cache=True)
def quat_mul(a, b):
    """Hamilton product a ⊗ b."""
    out = np.empty(4)
    out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3]
    out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2]
    out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1]
    out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]
    return out


@njit(cache=True)
def quat_to_mat(q):
    """Rotation matrix of a unit quaternion (w, x, y, z)."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    R = np.empty((3, 3))
    R[0, 0] = 1.0 - 2.0 * (y * y + z * z)
    R[0, 1] = 2.0 * (x * y - w * z)
    R[0, 2] = 2.0 * (x * z + w * y)
    R[1, 0] = 2.0 * (x * y + w * z)
    R[1, 1] = 1.0 - 2.0 * (x * x + z * z)
    R[1, 2] = 2.0 * (y * z - w * x)
    R[2, 0] = 2.0 * (x * z - w * y)
    R[2, 1] = 2.0 * (y * z + w * x)
    R[2, 2] = 1.0 - 2.0 * (x * x + y * y)
    return R


@njit(cache=True)
def quat_from_rotvec(r):
    """Exponential map: quaternion of a rotation vector (angle * axis)."""
    ang = math.sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
    out = np.empty(4)
    if ang < 1e-12:
        out[0] = 1.0
        out[1] = 0.5 * r[0]
        out[2] = 0.5 * r[1]
        out[3] = 0.5 * r[2]
    else:
        s = math.sin(0.5 * ang) / ang
        out[0] = math.cos(0.5 * ang)
        out[1] = s * r[0]
        out[2] = s * r[1]
        out[3] = s * r[2]
    return out


@njit(cache=True)
def mat_to_rotvec(R):
    """Logarithm map of a rotation matrix (angle in [0, pi])."""
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    c = min(1.0, max(-1.0, c))
    ang = math.acos(c)
    v = np.empty(3)
    v[0] = R[2, 1] - R[1, 2]
    v[1] = R[0, 2] - R[2, 0]
    v[2] = R[1, 0] - R[0, 1]
    s = math.sin(ang)
    if s > 1e-8:
        f = ang / (2.0 * s)
        v *= f
    elif ang < 1e-4:
        v *= 0.5
    else:  # angle close to pi: axis from the diagonal
        ax = np.empty(3)
        for k in range(3):
            ax[k] = math.sqrt(max(0.0, 0.5 * (R[k, k] + 1.0)))
        if ax[0] >= ax[1] and ax[0] >= ax[2]:
            ax[1] = math.copysign(ax[1], R[0, 1] + R[1, 0])
            ax[2] = math.copysign(ax[2], R[0, 2] + R[2, 0])
        elif ax[1] >= ax[2]:
            ax[0] = math.copysign(ax[0], R[0, 1] + R[1, 0])
            ax[2] = math.copysign(ax[2], R[1, 2] + R[2, 1])
        else:
            ax[0] = math.copysign(ax[0], R[0, 2] + R[2, 0])
            ax[1] = math.copysign(ax[1], R[1, 2] + R[2, 1])
        n = math.sqrt(ax[0] ** 2 + ax[1] ** 2 + ax[2] ** 2)
        v = ax * (ang / n)
    return v


@njit(cache=True)
def cross(a, b):
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True)
def integrate_bodies(pos, quat, vel, omega_b, kind, h):
    """Semi-implicit position update: x += h v, q <- q ⊗ exp(h ω_body), with the step's end
    velocities (those the joint and contact rows hold), of every body but the fixed ones
    (``kind`` 1, System.FIXED: never moved, as a Chrono body with SetFixed(true)).  With the midpoint gyroscopic term of
    :func:`sphdvi.dvi._kernels.free_velocity` a torque-free body keeps |L| and its energy to
    round-off, but the direction of L drifts at first order in h (the attitude takes ω₁, not
    the midpoint's Cayley rotation): 1.1e-4 over 2 s at h = 1e-3 for J = diag(0.01, 0.02,
    0.03), ω₀ = (1, 0.2, 3)."""
    nb = pos.shape[0]
    for i in range(nb):
        if kind[i] == 1:
            continue
        for k in range(3):
            pos[i, k] += h * vel[i, k]
        dq = quat_from_rotvec(h * omega_b[i])
        qn = quat_mul(quat[i], dq)
        n = math.sqrt(qn[0] ** 2 + qn[1] ** 2 + qn[2] ** 2 + qn[3] ** 2)
        for k in range(4):
            quat[i, k] = qn[k] / n


@njit(cache=True)
def body_rotations(quat):
    nb = quat.shape[0]
    R = np.empty((nb, 3, 3))
    for i in range(nb):
        R[i] = quat_to_mat(quat[i])
    return R


# ---------------------------------------------------------------- numpy side
def np_quat_to_mat(q):
    return quat_to_mat(np.asarray(q, dtype=np.float64))


def np_mat_to_quat(R):
    """Rotation matrix to unit quaternion (Shepperd's method), w >= 0."""
    R = np.asarray(R, dtype=np.float64)
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s]
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        q = [(R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s]
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * math.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        q = [(R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        q = [(R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    if q[0] < 0:
        q = -q
    return q / np.linalg.norm(q)


def frame_from_axis(axis, hint=None):
    """Orthonormal frame (columns x, y, z) whose z column is ``axis``."""
    z = np.asarray(axis, dtype=np.float64)
    z = z / np.linalg.norm(z)
    if hint is not None:
        x = np.asarray(hint, dtype=np.float64)
        x = x - z * (x @ z)
        if np.linalg.norm(x) < 1e-9:
            hint = None
    if hint is None:
        a = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        x = a - z * (a @ z)
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


def quat_to_euler_deg(q):
    """Roll, pitch, yaw in degrees (intrinsic Z-Y'-X'' i.e. R = Rz(yaw) Ry(pitch) Rx(roll)).

    ``q`` may be (4,) or (n, 4)."""
    q = np.atleast_2d(np.asarray(q, dtype=np.float64))
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.degrees(np.column_stack([roll, pitch, yaw]))
