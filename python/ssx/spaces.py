"""Observation and action spaces for ssx.learn.

When gymnasium is importable its spaces are used (`box` and `Dict` return gymnasium.spaces
objects); when it is not (Debian 12 does not package it) these minimal ones stand in with the same
names and behaviour for what learning code reads of a space: `shape`, `dtype`, `low`, `high`,
`sample()`, `contains()`, `seed()`.
"""
from __future__ import annotations

import numpy as np

try:
    import gymnasium as _gymnasium
except ImportError:
    _gymnasium = None


class Box:
    """A box in R^n: every element between its `low` and `high` (either may be infinite)."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        self.dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        self.shape = tuple(int(n) for n in shape)
        self.low = np.broadcast_to(np.asarray(low, dtype=self.dtype), self.shape).copy()
        self.high = np.broadcast_to(np.asarray(high, dtype=self.dtype), self.shape).copy()
        if np.any(self.low > self.high):
            raise ValueError("ssx.spaces.Box: low above high")
        self._rng = np.random.default_rng(seed)

    @property
    def np_random(self):
        return self._rng

    def seed(self, seed=None):
        self._rng = np.random.default_rng(seed)
        return [seed]

    def sample(self):
        """Uniform where both bounds are finite, normal where neither is, exponential from the
        finite side where one is."""
        low, high = self.low.astype(np.float64), self.high.astype(np.float64)
        finite_low, finite_high = np.isfinite(low), np.isfinite(high)
        out = np.empty(self.shape)
        both = finite_low & finite_high
        out[both] = self._rng.uniform(low[both], high[both])
        neither = ~finite_low & ~finite_high
        out[neither] = self._rng.normal(size=int(neither.sum()))
        above = finite_low & ~finite_high
        out[above] = low[above] + self._rng.exponential(size=int(above.sum()))
        below = ~finite_low & finite_high
        out[below] = high[below] - self._rng.exponential(size=int(below.sum()))
        return out.astype(self.dtype)

    def contains(self, x):
        x = np.asarray(x)
        if x.shape != self.shape or not np.can_cast(x.dtype, self.dtype, casting="same_kind"):
            return False
        return bool(np.all(x >= self.low) and np.all(x <= self.high))

    def __contains__(self, x):
        return self.contains(x)

    def __eq__(self, other):
        return (isinstance(other, Box) and self.shape == other.shape and self.dtype == other.dtype
                and np.array_equal(self.low, other.low) and np.array_equal(self.high, other.high))

    def __repr__(self):
        return f"Box({self.low.min()}, {self.high.max()}, {self.shape}, {self.dtype})"


class Dict:
    """Named spaces; a sample is a dict of their samples."""

    def __init__(self, spaces, seed=None):
        self.spaces = dict(spaces)
        self.seed(seed)

    def seed(self, seed=None):
        seeds = np.random.SeedSequence(seed).spawn(len(self.spaces))
        for (name, space), s in zip(self.spaces.items(), seeds):
            space.seed(int(s.generate_state(1)[0]))
        return [seed]

    def sample(self):
        return {name: space.sample() for name, space in self.spaces.items()}

    def contains(self, x):
        return (isinstance(x, dict) and x.keys() == self.spaces.keys()
                and all(space.contains(x[name]) for name, space in self.spaces.items()))

    def __contains__(self, x):
        return self.contains(x)

    def __getitem__(self, name):
        return self.spaces[name]

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k}: {v!r}" for k, v in self.spaces.items()) + ")"


def make_box(low, high, shape, dtype=np.float32):
    """A Box: gymnasium's when it is importable, else this module's."""
    if _gymnasium is not None:
        return _gymnasium.spaces.Box(low=low, high=high, shape=shape, dtype=dtype)
    return Box(low, high, shape, dtype)


def box(single, n):
    """The batch of `n` of a Box `single` (what a vector environment's observation_space is)."""
    if _gymnasium is not None and isinstance(single, _gymnasium.spaces.Space):
        from gymnasium.vector.utils import batch_space

        return batch_space(single, n)
    return Box(np.broadcast_to(single.low, (n,) + single.shape), np.broadcast_to(single.high, (n,) + single.shape),
               (n,) + single.shape, single.dtype)
