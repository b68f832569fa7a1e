"""Explicit Runge–Kutta pairs as data: Butcher tableaux, error weights, dense output.

One step routine (``csrc/pl_explicit.c``) runs any of them; a method is added by adding
its tableau here and a line to :data:`posturelab.simulation.compiled.METHODS`.

Each tableau is first-same-as-last (FSAL): its last row of ``A`` is its solution
weights, so the last stage is f(t + h, y_new), the first stage of the next step.
The dense output is y_old + Σ_k Q_k σ^(k+1), σ = (t − t_old)/h, with
Q = h Kᵀ P (K the stages), padded to four coefficients.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Tableau", "DORMAND_PRINCE_54", "BOGACKI_SHAMPINE_32"]


@dataclass(frozen=True)
class Tableau:
    """An explicit embedded Runge–Kutta pair.

    Attributes
    ----------
    name : str
        As scipy names it.
    A : numpy.ndarray, shape (S, S)
        Stage coefficients (row S − 1 is the solution weights b). [-]
    nodes : numpy.ndarray, shape (S,)
        c: stage times as fractions of the step. [-]
    error : numpy.ndarray, shape (S,)
        Weights of the embedded error estimate h Σ_j e_j K_j. [-]
    dense : numpy.ndarray, shape (S, 4)
        P of the dense output (columns for σ … σ⁴). [-]
    error_order : int
        Order q of the error estimate; the step-size controller uses 1/(q + 1). [-]
    source : str
        Where the numbers come from.
    """

    name: str
    A: np.ndarray
    nodes: np.ndarray
    error: np.ndarray
    dense: np.ndarray
    error_order: int
    source: str

    def __post_init__(self) -> None:
        for arr in (self.A, self.nodes, self.error, self.dense):
            arr.setflags(write=False)


def _dormand_prince() -> Tableau:
    A = np.zeros((7, 7))
    A[1, :1] = [1 / 5]
    A[2, :2] = [3 / 40, 9 / 40]
    A[3, :3] = [44 / 45, -56 / 15, 32 / 9]
    A[4, :4] = [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729]
    A[5, :5] = [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656]
    A[6, :6] = [35 / 384, 0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84]
    nodes = np.array([0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1, 1])
    error = np.array([-71 / 57600, 0, 71 / 16695, -71 / 1920, 17253 / 339200, -22 / 525,
                      1 / 40])
    dense = np.array([
        [1, -8048581381 / 2820520608, 8663915743 / 2820520608, -12715105075 / 11282082432],
        [0, 0, 0, 0],
        [0, 131558114200 / 32700410799, -68118460800 / 10900136933,
         87487479700 / 32700410799],
        [0, -1754552775 / 470086768, 14199869525 / 1410260304, -10690763975 / 1880347072],
        [0, 127303824393 / 49829197408, -318862633887 / 49829197408,
         701980252875 / 199316789632],
        [0, -282668133 / 205662961, 2019193451 / 616988883, -1453857185 / 822651844],
        [0, 40617522 / 29380423, -110615467 / 29380423, 69997945 / 29380423],
    ])
    return Tableau("RK45", A, nodes, error, dense, 4,
                   "Dormand & Prince (1980); error estimate and the free 4th-order dense "
                   "output (Shampine's c6) as in scipy.integrate.RK45")


def _bogacki_shampine() -> Tableau:
    A = np.zeros((4, 4))
    A[1, :1] = [1 / 2]
    A[2, :2] = [0, 3 / 4]
    A[3, :3] = [2 / 9, 1 / 3, 4 / 9]
    nodes = np.array([0, 1 / 2, 3 / 4, 1])
    error = np.array([5 / 72, -1 / 12, -1 / 9, 1 / 8])
    dense = np.array([[1, -4 / 3, 5 / 9, 0], [0, 1, -2 / 3, 0], [0, 4 / 3, -8 / 9, 0],
                      [0, -1, 1, 0]])
    return Tableau("RK23", A, nodes, error, dense, 2,
                   "Bogacki & Shampine (1989); cubic Hermite dense output as in "
                   "scipy.integrate.RK23")


#: scipy's RK45.
DORMAND_PRINCE_54 = _dormand_prince()
#: scipy's RK23.
BOGACKI_SHAMPINE_32 = _bogacki_shampine()
