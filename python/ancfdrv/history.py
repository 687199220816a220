"""Post-processing of time histories: the luffing stages of SPEC section 5, their
min/max, and the dominant frequency and amplitude of the vibration stage."""
from __future__ import annotations

import functools

import numpy as np

STAGES = ("start", "luffing", "braking", "vibration")


def luffing_stage_bounds(omega: float, t_start: float, t_brake: float, sweep: float,
                         t_end: float) -> dict[str, tuple[float, float]]:
    """[t0, t1) of each stage: start [0, t_s), luffing [t_s, t1), braking [t1, t2),
    steady-state vibration [t2, t_end]."""
    t_c = sweep / omega - 0.5 * (t_start + t_brake)
    t1 = t_start + t_c
    t2 = t1 + t_brake
    return {"start": (0.0, t_start), "luffing": (t_start, t1), "braking": (t1, t2),
            "vibration": (t2, t_end)}


@functools.lru_cache(maxsize=64)
def fast_length(n: int) -> int:
    """The smallest 5-smooth number (2^a 3^b 5^c) at least ``n``: a length the FFT
    transforms in O(n log n) with small radices (a length with a large prime factor takes
    Bluestein's algorithm, several times slower)."""
    best = 1 << max(n - 1, 0).bit_length()   # the next power of two: an upper bound
    five = 1
    while five < best:
        three = five
        while three < best:
            two = three
            while two < n:
                two *= 2
            best = min(best, two)
            three *= 3
        five *= 5
    return best


def dominant_frequency(time: np.ndarray, signal: np.ndarray) -> tuple[float, float]:
    """Dominant frequency (Hz) of a uniformly sampled signal, from the peak of its
    Hann-windowed spectrum refined by parabolic interpolation, and the amplitude
    (half the peak-to-peak of the mean-free signal). The record is zero-padded to at
    least 8 times its length (bins 1/8 of the record's resolution), to a fast length
    (:func:`fast_length`)."""
    if len(time) < 8:
        return float("nan"), float("nan")
    y = signal - signal.mean()
    dt = float(np.mean(np.diff(time)))
    n = fast_length(8 * len(y))
    spectrum = np.abs(np.fft.rfft(y * np.hanning(len(y)), n))
    k = int(np.argmax(spectrum[1:])) + 1
    if 1 <= k < len(spectrum) - 1:
        a, b, c = np.log(spectrum[k - 1:k + 2] + 1e-300)
        k = k + 0.5 * (a - c) / (a - 2 * b + c)
    return k / (n * dt), 0.5 * float(y.max() - y.min())


def stage_summary(time: np.ndarray, transverse: np.ndarray,
                  bounds: dict[str, tuple[float, float]]) -> dict[str, float]:
    """min/max of the transverse tip deflection per stage; frequency and amplitude of the
    vibration stage. ``time`` ascends (the output rows): each stage is a slice of the rows,
    [t0, t1) (the vibration stage [t0, t1])."""
    out: dict[str, float] = {}
    for stage, (t0, t1) in bounds.items():
        first = int(np.searchsorted(time, t0, side="left"))
        stop = int(np.searchsorted(time, t1, side="right" if stage == "vibration" else "left"))
        if stop <= first:
            continue
        values = transverse[first:stop]
        out[f"{stage}_t0"], out[f"{stage}_t1"] = t0, t1
        out[f"{stage}_min"] = float(values.min())
        out[f"{stage}_max"] = float(values.max())
        if stage == "vibration":
            # contiguous copies, as the stage's rows picked by a mask were (the sums of
            # the mean and the spectrum run over them in the same order)
            values = np.array(values)
            freq, amp = dominant_frequency(np.array(time[first:stop]), values)
            out["vibration_frequency_hz"] = freq
            out["vibration_amplitude"] = amp
            out["vibration_mean"] = float(values.mean())
    return out


def crossing_frequency(time: np.ndarray, signal: np.ndarray) -> float:
    """Frequency (Hz) from the upward zero crossings of the mean-free signal, located by
    linear interpolation: precise for a clean, nearly harmonic record of many periods."""
    y = signal - signal.mean()
    up = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    if len(up) < 2:
        return float("nan")
    crossings = time[up] - y[up] * (time[up + 1] - time[up]) / (y[up + 1] - y[up])
    return (len(crossings) - 1) / (crossings[-1] - crossings[0])
