"""The series a run derives from its states: torques, moments, accelerations, centre of
gravity, ground reaction, centre of pressure, platform motion.

One numpy computation from the model functions serves both engines (the compiled
engine calls it when a result's derived series are first read).
"""

from __future__ import annotations

import numpy as np

from ..model.dynamics import angular_acceleration, mass_matrix
from ..model.joint_feedback import joint_feedback_moments
from ..model.kinematics import (
    centre_of_gravity,
    centre_of_gravity_velocity,
    centre_of_pressure,
    ground_reaction,
)
from ..model.muscles import feedback_pair_torques, moments_to_link_torques
from ..model.noise import torque_at
from .results import DerivedSeries
from .setup import RunSetup, platform_acceleration, tilt_torques

__all__ = ["derived_series"]


def derived_series(setup: RunSetup, time: np.ndarray, state: np.ndarray,
                   feedback_state: np.ndarray | None = None,
                   locked: np.ndarray | None = None,
                   filter_state: np.ndarray | None = None) -> DerivedSeries:
    """The derived series of a run.

    Parameters
    ----------
    setup : RunSetup
        The run.
    time : numpy.ndarray, shape (T,)
        Sample times. [s]
    state : numpy.ndarray, shape (T, 2N)
        ``[Θ, Θ̇]`` at the samples. [rad], [rad/s]
    feedback_state : numpy.ndarray, shape (T, 2N), optional
        The state the delayed part of the feedback responded to at each sample
        (x(t − τ)); ``state`` by default. [rad], [rad/s]
    locked : numpy.ndarray of bool, shape (T,), optional
        Samples at which the knee constraint held.
    filter_state : numpy.ndarray, shape (T, P), optional
        The torque feedback filters' states Y at the samples, added to their pairs'
        torques (:func:`posturelab.model.switched.torque_feedback_rate`). [N·m]

    Returns
    -------
    DerivedSeries
        Pair torques are zero while a one-sided pair's fed-back stretch is negative;
        joint moments are clipped to the torque limits.
    """
    body, muscles = setup.body, setup.muscles
    n = body.n_links
    time = np.asarray(time, dtype=float)
    state = np.asarray(state, dtype=float).reshape(-1, 2 * n)
    theta, omega = state[:, :n], state[:, n:]
    fb = state if feedback_state is None else np.asarray(feedback_state, dtype=float)
    M = feedback_pair_torques(muscles, setup.gains, state, fb)
    if filter_state is not None:
        M = M + np.asarray(filter_state, dtype=float)
    if muscles.one_sided_mask.any():  # (such pairs are all-immediate or all-delayed)
        slack = muscles.one_sided_mask & (fb[:, :n] @ muscles.selection_matrix.T < 0.0)
        slack |= muscles.pull_only_mask & (M < 0.0)  # a pull-only pair does not push
        M = np.where(slack, 0.0, M)
    if setup.tilt is not None:
        M = M + tilt_torques(setup.tilt, setup.tilt_gains, setup.feedback_delay, time)
    if setup.visual_tilt is not None:
        M = M + tilt_torques(setup.visual_tilt, setup.visual_gains, setup.feedback_delay, time)
    moments = M @ muscles.crossing_matrix
    control = setup.options.joint_feedback is not None
    if control:  # the joint-space controller's moments (posturelab.model.joint_feedback)
        moments = moments + joint_feedback_moments(setup.joint_gains, state, fb)
    if setup.motor_torque is not None:
        moments = moments + torque_at(setup.motor_torque, time)
    if setup.torque_limits is not None:
        moments = np.clip(moments, -setup.torque_limits, setup.torque_limits)
    if setup.torque_limits is not None or setup.motor_torque is not None or control:
        U = moments_to_link_torques(moments)
    else:
        U = -M @ muscles.selection_matrix
    acc = platform_acceleration(setup, time)
    alpha = (angular_acceleration(body, theta, omega, U, acc[:, 0], acc[:, 1]) if time.size
             else np.zeros((0, n)))
    if locked is not None and setup.knee_row is not None and np.any(locked):
        row = setup.knee_row
        J = mass_matrix(body, theta[locked])
        JiC = np.linalg.solve(J, np.broadcast_to(row, (int(locked.sum()), n))[..., None])[..., 0]
        alpha[locked] -= JiC * ((alpha[locked] @ row) / (JiC @ row))[:, None]
    ground = ground_reaction(body, theta, omega, alpha, acc)
    cop = centre_of_pressure(moments[:, 0], ground[:, 1])
    vel = np.zeros_like(acc)
    pos = np.zeros_like(acc)
    if time.size > 1:
        dt = np.diff(time)[:, None]
        vel[1:] = np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt, axis=0)
        vel += np.array(setup.velocity_jump)
        pos[1:] = np.cumsum(0.5 * (vel[1:] + vel[:-1]) * dt, axis=0)
    elif time.size == 1:
        vel[:] = setup.velocity_jump
    alpha.setflags(write=False)
    return DerivedSeries(
        pair_torques=M, joint_torques=U, joint_moments=moments,
        cog_position=centre_of_gravity(body, theta),
        cog_velocity=centre_of_gravity_velocity(body, theta, omega),
        platform_acceleration=acc, platform_velocity=vel, platform_position=pos,
        angular_acceleration=alpha, ground_reaction=ground, centre_of_pressure=cop,
        com_angle=theta @ body.gravity_coefficients / body.gravity_coefficients.sum(),
        tilt=None if setup.tilt is None else setup.tilt.angle(time),
        visual_tilt=None if setup.visual_tilt is None else setup.visual_tilt.angle(time),
    )
