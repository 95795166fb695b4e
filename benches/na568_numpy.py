#!/usr/bin/env python3
"""The NA 568 / ROB 530 SE(2) Monte Carlo workload in NumPy/SciPy, written the way the
lecture's Python script computes it (a matrix per particle, scipy.linalg.expm for every
noise sample, scipy.linalg.logm for every particle in every Lie-mean iteration), for
comparison with `benches/na568.rs` (BENCHMARKS.md).

Workload (REFERENCE_CASES.md R2): X_{k+1} = X_k U_k expm(w_k^), w_k ~ N(0, Q),
Q = diag(0.03^2, 0.03^2, 0.1^2) in (v1, v2, omega), 1000 particles from X_0 = I, 7 steps;
after every step the iterative Lie sample mean (start: the first particle;
mu <- mu expm(mean_i logm(mu^-1 X_i)) until |logm(mu_old^-1 mu_new)| < 1e-8, at most 100
iterations) and the 1/(N-1) covariance of the vee'd logm tangents.

Prints one JSON line with the timings (wall seconds, and CPU seconds of this process, which
the load of a shared machine inflates less) and the last step's statistics.
"""

import argparse
import json
import time

import numpy as np
from scipy.linalg import expm, logm

U1 = 0.6
U2 = [0.043333, 0.062110, 0.089025, 0.127602, 0.182895, 0.262149, 0.375746]
U3 = [0.072096, 0.031054, 0.044150, 0.062248, 0.086330, 0.116042, 0.147573]

Q = np.diag([0.03**2, 0.03**2, 0.1**2])

# se(2) generators for (v1, v2, omega).
E1 = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
E2 = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
E3 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])


def increment(u1, u2, u3):
    """U = [[R(u3), (u1, u2)^T], [0 0 1]]."""
    c, s = np.cos(u3), np.sin(u3)
    return np.array([[c, -s, u1], [s, c, u2], [0.0, 0.0, 1.0]])


def vee(a):
    return np.array([a[0, 2], a[1, 2], a[1, 0]])


def propagate(particles, u, chol, rng):
    """Moves every particle by U exp(w^), one 3x3 expm per particle."""
    for i in range(len(particles)):
        w = chol @ rng.standard_normal(3)
        particles[i] = particles[i] @ u @ expm(E1 * w[0] + E2 * w[1] + E3 * w[2])


def lie_sample_statistics(particles, tolerance=1e-8, max_iter=100):
    """Iterative Lie mean from the first particle and the 1/(N-1) covariance (lecture form)."""
    n = len(particles)
    mu0 = particles[0]
    for iteration in range(1, max_iter + 1):
        mean_algebra = np.zeros((3, 3))
        sigma = np.zeros((3, 3))
        mu0_inv = np.linalg.inv(mu0)
        for x in particles:
            v = logm(mu0_inv @ x)
            mean_algebra = mean_algebra + v
            xi = vee(v)
            sigma = sigma + np.outer(xi, xi)
        mu = mu0 @ expm(mean_algebra / n)
        sigma = sigma / (n - 1)
        if np.linalg.norm(logm(np.linalg.inv(mu0) @ mu)) < tolerance:
            return mu, sigma, iteration
        mu0 = mu
    raise RuntimeError("Lie mean did not converge")


def workload(particles_count, seed):
    rng = np.random.default_rng(seed)
    chol = np.linalg.cholesky(Q)
    particles = [np.eye(3) for _ in range(particles_count)]
    stats = []
    for k in range(7):
        propagate(particles, increment(U1, U2[k], U3[k]), chol, rng)
        stats.append(lie_sample_statistics(particles))
    return stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=568)
    args = parser.parse_args()

    times = []
    cpu_times = []
    stats = None
    for r in range(args.repeats):
        start, cpu_start = time.perf_counter(), time.process_time()
        stats = workload(args.particles, args.seed + r)
        times.append(time.perf_counter() - start)
        cpu_times.append(time.process_time() - cpu_start)
    mu, sigma, iterations = stats[-1]
    print(
        json.dumps(
            {
                "workload": "na568_se2",
                "particles": args.particles,
                "steps": 7,
                "seconds": times,
                "min_seconds": min(times),
                "median_seconds": float(np.median(times)),
                "cpu_seconds": cpu_times,
                "last_mean_xy_theta": [mu[0, 2], mu[1, 2], float(np.arctan2(mu[1, 0], mu[0, 0]))],
                "last_cov_diag": np.diag(sigma).tolist(),
                "iterations_per_step": [s[2] for s in stats],
                "numpy": np.__version__,
                "scipy": __import__("scipy").__version__,
            }
        )
    )


if __name__ == "__main__":
    main()
