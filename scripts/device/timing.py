"""The device scripts' timing: the best wall time of n calls after a warm-up call."""
import time


def best(f, n=3):
    f()
    times = []
    for _ in range(n):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)
