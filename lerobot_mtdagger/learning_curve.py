"""Per-task learning curves fitted online, and the split that follows their expected gain per demo.

The model of the ``curve`` scheduler: task i's success after ``n`` expert demos is
``sigmoid(a_i + b_i * log n)``, each task's intercept and slope shrunk toward the tasks' common ones
so that the first rounds, where every task sits at the same demos, still give a curve. Pure numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NEWTON_STEPS = 25
"""Newton iterations of the curve fit (at most; it stops when converged)."""


@dataclass(frozen=True)
class CurvePrior:
    """The shrinkage of the curve fit (standard deviations of normal priors).

    Attributes:
        prior_scale: A task's intercept around the common one (logits).
        slope_mean: Prior mean of the tasks' common slope on log demos.
        slope_scale: That common slope's prior standard deviation.
        task_slope_scale: A task's slope around the common one (small: one slope for all tasks).
    """

    prior_scale: float = 1.5
    slope_mean: float = 1.0
    slope_scale: float = 1.0
    task_slope_scale: float = 0.1


@dataclass(frozen=True)
class FittedCurves:
    """The fitted curves: ``sigmoid(intercept[i] + slope[i] * log n)``.

    Attributes:
        intercept: One logit intercept per task, shape (num_tasks,).
        slope: One slope on log demos per task, shape (num_tasks,).
    """

    intercept: np.ndarray
    slope: np.ndarray

    def success(self, demos: np.ndarray) -> np.ndarray:
        """Predicted success at ``demos``, shape (num_tasks,) or (num_tasks, K)."""
        demos = np.maximum(np.asarray(demos, dtype=np.float64), 1.0)
        shape = (-1,) + (1,) * (demos.ndim - 1)
        return _sigmoid(self.intercept.reshape(shape) + self.slope.reshape(shape) * np.log(demos))


def _sigmoid(x: np.ndarray) -> np.ndarray:
    return 0.5 * (1.0 + np.tanh(0.5 * x))


def fit_logistic_curves(
    demos: np.ndarray, success: np.ndarray, episodes: np.ndarray, prior: CurvePrior
) -> FittedCurves:
    """Fits the shrunk logistic curves to a history of measurements (penalised maximum likelihood).

    Damped Newton ascent of the penalised binomial log-likelihood over each task's intercept and slope
    and the common two (``2 * num_tasks + 2`` unknowns), each step in O(num_tasks).

    Args:
        demos: Expert demos per task behind each measurement, shape (rounds, num_tasks).
        success: Measured success rate, shape (rounds, num_tasks); ignored where ``episodes`` is 0.
        episodes: Episodes behind each rate, shape (rounds, num_tasks).
        prior: The shrinkage.
    """
    demos, success, episodes = (np.asarray(a, dtype=np.float64) for a in (demos, success, episodes))
    data = _Data(
        np.log(np.maximum(demos, 1.0)),
        np.where(episodes > 0, episodes, 0.0),
        np.where(episodes > 0, np.nan_to_num(success), 0.0),
    )
    num_tasks = demos.shape[1]
    theta = np.concatenate(
        [np.zeros(num_tasks), np.full(num_tasks, prior.slope_mean), [0.0, prior.slope_mean]]
    )
    value = _objective(theta, data, prior)
    for _ in range(NEWTON_STEPS):
        step = _newton_step(theta, data, prior)
        # Backtracking: a full Newton step can overshoot where a task's rate is 0 or 1.
        for _ in range(30):
            candidate = theta + step
            new_value = _objective(candidate, data, prior)
            if new_value >= value - 1e-12:
                break
            step = step / 2.0
        theta, previous, value = candidate, value, new_value
        if np.abs(step).max() < 1e-8 or abs(value - previous) < 1e-10:
            break
    return FittedCurves(theta[:num_tasks].copy(), theta[num_tasks : 2 * num_tasks].copy())


@dataclass(frozen=True)
class _Data:
    x: np.ndarray  # log demos, (R, N)
    weight: np.ndarray  # episodes, (R, N)
    rate: np.ndarray  # success rates, (R, N)


def _split(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, float, float]:
    num_tasks = (theta.size - 2) // 2
    return theta[:num_tasks], theta[num_tasks : 2 * num_tasks], float(theta[-2]), float(theta[-1])


def _objective(theta: np.ndarray, data: _Data, prior: CurvePrior) -> float:
    """Penalised log-likelihood (to maximise)."""
    intercept, slope, common, common_slope = _split(theta)
    logits = intercept[None, :] + slope[None, :] * data.x
    log_p, log_q = -np.logaddexp(0.0, -logits), -np.logaddexp(0.0, logits)
    fit = float((data.weight * (data.rate * log_p + (1.0 - data.rate) * log_q)).sum())
    penalty = (
        ((intercept - common) ** 2).sum() / prior.prior_scale**2
        + ((slope - common_slope) ** 2).sum() / prior.task_slope_scale**2
        + (common_slope - prior.slope_mean) ** 2 / prior.slope_scale**2
        + common**2 / 100.0
    )
    return fit - 0.5 * penalty


def _newton_step(theta: np.ndarray, data: _Data, prior: CurvePrior) -> np.ndarray:
    """The Newton step at ``theta``, in O(num_tasks) by the Schur complement of the two common parameters.

    The negative Hessian is block-diagonal over tasks (intercept and slope) bordered by those two.
    """
    intercept, slope, common, common_slope = _split(theta)
    tau2, sigma2, slope2 = prior.prior_scale**2, prior.task_slope_scale**2, prior.slope_scale**2
    p = _sigmoid(intercept[None, :] + slope[None, :] * data.x)
    residual = data.weight * (data.rate - p)  # (R, N)
    curvature = data.weight * p * (1.0 - p)
    grad_a = residual.sum(0) - (intercept - common) / tau2
    grad_b = (residual * data.x).sum(0) - (slope - common_slope) / sigma2
    grad_h = np.array(
        [
            (intercept - common).sum() / tau2 - common / 100.0,
            (slope - common_slope).sum() / sigma2 - (common_slope - prior.slope_mean) / slope2,
        ]
    )
    h_aa = curvature.sum(0) + 1.0 / tau2
    h_bb = (curvature * data.x**2).sum(0) + 1.0 / sigma2
    h_ab = (curvature * data.x).sum(0)
    det = h_aa * h_bb - h_ab**2

    def solve_blocks(g_a: np.ndarray, g_b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (h_bb * g_a - h_ab * g_b) / det, (h_aa * g_b - h_ab * g_a) / det

    # Border: intercepts couple to the common intercept (-1/tau2), slopes to the common slope (-1/sigma2).
    zeros, n = np.zeros_like(h_aa), h_aa.size
    mu_a, mu_b = solve_blocks(np.full(n, -1.0 / tau2), zeros)
    beta_a, beta_b = solve_blocks(zeros, np.full(n, -1.0 / sigma2))
    g_a, g_b = solve_blocks(grad_a, grad_b)
    schur = np.array([[n / tau2 + 1.0 / 100.0, 0.0], [0.0, n / sigma2 + 1.0 / slope2]])
    schur -= np.array(
        [
            [(mu_a * -1.0 / tau2).sum(), (beta_a * -1.0 / tau2).sum()],
            [(mu_b * -1.0 / sigma2).sum(), (beta_b * -1.0 / sigma2).sum()],
        ]
    )
    rhs = grad_h - np.array([(g_a * -1.0 / tau2).sum(), (g_b * -1.0 / sigma2).sum()])
    step_h = np.linalg.solve(schur, rhs)
    step_a = g_a - (mu_a * step_h[0] + beta_a * step_h[1])
    step_b = g_b - (mu_b * step_h[0] + beta_b * step_h[1])
    return np.concatenate([step_a, step_b, step_h])


def greedy_split(curve: np.ndarray, budget: int, n_min: int) -> tuple[np.ndarray, np.ndarray]:
    """Splits ``budget`` demos where each task's curve rises most per demo.

    Every task first gets ``n_min``; then the demos go, one by one, to the largest next gain per demo of
    each task's least concave majorant (a curve flat before it rises is valued by its best average rise).
    On concave curves this is the exact optimum of the mean success; demos no curve values any more are
    spread evenly.

    Args:
        curve: Success of task i after ``j`` more demos, shape (num_tasks, budget + 1).
        budget: Demos to hand out (>= n_min * num_tasks).
        n_min: Demos every task gets first.

    Returns:
        ``(counts, rate)``: demos per task (int64, summing to ``budget``) and each task's best gain
        per demo after its ``n_min``, shape (num_tasks,).
    """
    num_tasks = curve.shape[0]
    counts = np.full(num_tasks, n_min, dtype=np.int64)
    remaining = budget - n_min * num_tasks
    slopes = _majorant_slopes(np.diff(curve[:, n_min:], axis=1))  # (num_tasks, budget - n_min)
    rate = slopes[:, 0] if slopes.shape[1] else np.zeros(num_tasks)
    if remaining > 0 and slopes.shape[1]:
        order = np.argsort(-slopes, axis=None, kind="stable")[:remaining]
        order = order[slopes.ravel()[order] > 0]
        counts += np.bincount(order // slopes.shape[1], minlength=num_tasks)
        remaining -= order.size
    counts += remaining // num_tasks
    for task in np.argsort(counts, kind="stable")[: remaining % num_tasks]:
        counts[task] += 1
    return counts, rate


def _majorant_slopes(marginals: np.ndarray) -> np.ndarray:
    """Each row's slopes of the least concave majorant of its cumulative sum (antitonic fit of its gains)."""
    slopes = marginals.copy()
    ones = np.ones(marginals.shape[1])
    for row in np.flatnonzero(np.any(np.diff(marginals, axis=1) > 1e-15, axis=1)):
        slopes[row] = -isotonic(-marginals[row], ones)
    return slopes


def isotonic(values: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """Weighted least-squares non-decreasing fit of ``values`` (shape (K,)) by pool adjacent violators."""
    blocks: list[list[float]] = []  # [weighted mean, weight, count]
    for value, weight in zip(values.tolist(), weights.tolist(), strict=True):
        blocks.append([value, weight, 1])
        while len(blocks) > 1 and blocks[-2][0] > blocks[-1][0]:
            mean_b, weight_b, count_b = blocks.pop()
            mean_a, weight_a, count_a = blocks.pop()
            total = weight_a + weight_b
            blocks.append([(mean_a * weight_a + mean_b * weight_b) / total, total, count_a + count_b])
    return np.concatenate([np.full(count, mean) for mean, _, count in blocks])
