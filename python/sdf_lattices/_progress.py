"""Progress of long calls (query, sample, render, ...): the extension calls
reporter(progress, label, total) once per call and the reporter's update(done, total)
about ten times a second from the calling thread, then close()."""
import sys
import time


class _Callback:
    def __init__(self, fn):
        self.fn = fn

    def update(self, done, total):
        self.fn(done, total)

    def close(self):
        pass


class _Tqdm:
    def __init__(self, tqdm, label, total):
        self.bar = tqdm(total=total, desc=label, unit="pt", unit_scale=True)

    def update(self, done, total):
        self.bar.update(done - self.bar.n)

    def close(self):
        self.bar.close()


class _Lines:
    """Without tqdm: a line on sys.stderr every 2 s (Python's stderr, so Jupyter shows it)."""

    def __init__(self, label, total, interval=2.0):
        self.label, self.total, self.interval = label, total, interval
        self.start = self.last = time.monotonic()
        self.printed = False

    def update(self, done, total):
        now = time.monotonic()
        if now - self.last < self.interval:
            return
        self.last = now
        self.printed = True
        print(f"  {self.label}: {100.0 * done / max(total, 1):5.1f}%  {now - self.start:.0f} s elapsed",
              file=sys.stderr, flush=True)

    def close(self):
        if self.printed:
            print(f"  {self.label}: done in {time.monotonic() - self.start:.1f} s", file=sys.stderr, flush=True)


def reporter(progress, label, total):
    """progress: True (a tqdm bar when tqdm is installed, else lines on sys.stderr) or a
    callable progress(done, total)."""
    if callable(progress):
        return _Callback(progress)
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return _Lines(label, total)
        return _Tqdm(tqdm, label, total)
    raise TypeError(f"progress: expected None, True, False or a callable progress(done, total), got {progress!r}")
