"""The reasoner: turns observation firings into property metrics (CLARC paper §3.4).

Each property is a hidden Boolean with prior odds ``reference/(1 - reference)``. A firing with
likelihood ratio LR is evidence with ``p = 1/(1+LR)``, ``q = LR/(1+LR)``; with age τ its evidence has
faded to ``p_τ = 1/2 + (p - 1/2)·d``, ``q_τ = 1/2 + (q - 1/2)·d``, ``d = exp(-2λτ)``, λ = 1/survival.
The metric is ``odds/(1 + odds)`` with ``odds = prior_odds · Π p_τ/q_τ``.

We work in log-odds. Since ``q = 1 - p``, a firing contributes ``log(p_τ/q_τ) = 2·atanh(u·d)`` with
``u = 2p - 1``. That is not a plain exponential in τ, so firings cannot simply be merged, and with
survival 100 min a firing's factor stays further than 1e-12 from 1 for about a day: pruning alone
would let the cost of an update grow all through a kiosk day. So a firing is kept on its own only while
``|u·d| > 1/2`` (a few minutes); after that it is folded into a power series
``2·atanh(x) = 2·Σ x^(2k+1)/(2k+1)``, whose k-th term decays exactly like ``exp(-2λ(2k+1)τ)`` and
can therefore be summed over all folded firings into one coefficient. With ``|x| ≤ 1/2`` and
``SERIES_TERMS`` terms the truncation error is below 2e-15 per firing, and shrinks as it ages.
A folded sum whose whole contribution is below ``PRUNE`` (every firing in it has a factor within
1e-12 of 1) is dropped. The cost of an update is thus bounded by the firings of the last
few minutes, however long the engine runs.
"""

from __future__ import annotations

import math

from qos.model import Property

#: a firing whose factor is within this of 1 (log-factor below it) carries no information any more
PRUNE = 1e-12
#: fold a firing into the series once |u·d| is at most this
FOLD_AT = 0.5
#: terms of the atanh series kept; 2·FOLD_AT^(2K+1)/((2K+1)(1-FOLD_AT²)) < 2e-15
SERIES_TERMS = 22


def _logistic(log_odds: float) -> float:
    if log_odds >= 0:
        return 1.0 / (1.0 + math.exp(-log_odds))
    odds = math.exp(log_odds)
    return odds / (1.0 + odds)


class _Evidence:
    """The firings that fade at one rate (a property's survival, or an action's own)."""

    def __init__(self, rate: float):
        #: twice the decay rate: d = exp(-rate·τ)
        self._rate = rate
        #: log-odds of evidence that never fades (no survival)
        self._lasting = 0.0
        #: lone firings: (time, u)
        self._recent: list[tuple[float, float]] = []
        #: series coefficients A_k, valid at time _series_t: contribution = Σ A_k·x^(2k+1)
        self._series = [0.0] * SERIES_TERMS
        self._series_t = 0.0
        self._series_live = False

    def add(self, t: float, likelihood_ratio: float) -> None:
        if self._rate == 0.0:
            self._lasting -= math.log(likelihood_ratio)
            return
        keep: list[tuple[float, float]] = []
        for fired_at, u in self._recent:
            x = u * math.exp(-self._rate * (t - fired_at))
            if abs(x) <= FOLD_AT:
                self._fold(t, x)
            else:
                keep.append((fired_at, u))
        keep.append((t, (1.0 - likelihood_ratio) / (1.0 + likelihood_ratio)))
        self._recent = keep

    def accumulate(self, total: float, t: float) -> float:
        """``total`` plus this evidence's log-odds at time t (added in a fixed order, for exact replays)."""
        total += self._lasting
        if self._rate == 0.0:
            return total
        for fired_at, u in self._recent:
            total += 2.0 * math.atanh(u * math.exp(-self._rate * (t - fired_at)))
        return total + self._series_value(t)

    def _rebase(self, t: float) -> None:
        """Move the series' reference time to t, decaying its coefficients."""
        if t == self._series_t:
            return
        x = math.exp(-self._rate * (t - self._series_t))
        x2, power = x * x, x
        series = self._series
        for k in range(SERIES_TERMS):
            series[k] *= power
            power *= x2
        self._series_t = t

    def _fold(self, t: float, x: float) -> None:
        self._rebase(t)
        if self._series_live and self._series_bound() < PRUNE:
            self._series = [0.0] * SERIES_TERMS  # everything folded so far has faded out
        x2, power = x * x, x
        series = self._series
        for k in range(SERIES_TERMS):
            series[k] += 2.0 * power / (2 * k + 1)
            power *= x2
        self._series_live = True

    def _series_bound(self) -> float:
        """An upper bound of the series' contribution now (at its reference time)."""
        return sum(abs(coefficient) for coefficient in self._series)

    def _series_value(self, t: float) -> float:
        if not self._series_live:
            return 0.0
        x = math.exp(-self._rate * (t - self._series_t))
        x2, power = x * x, x
        value = bound = 0.0
        for coefficient in self._series:
            term = coefficient * power
            value += term
            bound += abs(term)
            power *= x2
        return value if bound >= PRUNE else 0.0

    @property
    def live_firings(self) -> int:
        return len(self._recent)


class PropertyBelief:
    """The evidence gathered for one property (or beliefvar), and its metric at any later time."""

    def __init__(self, prop: Property):
        self.property = prop
        self._prior = math.log(prop.prior / (1.0 - prop.prior))
        self._rate = 2.0 * prop.decay_rate
        #: evidence by fading rate; the property's own rate first
        self._pools: dict[float, _Evidence] = {self._rate: _Evidence(self._rate)}

    def add(self, t: float, likelihood_ratio: float, survival: float | None = None) -> None:
        """Record a firing at time t that fades with ``survival`` seconds (default: the property's);
        times of successive calls must not decrease.

        Lone firings that have faded to ``|u·d| ≤ FOLD_AT`` by t are folded into the series here,
        so that reading a metric stays a pure function of time.
        """
        rate = self._rate if survival is None else 2.0 / survival
        pool = self._pools.get(rate)
        if pool is None:
            pool = self._pools[rate] = _Evidence(rate)
        pool.add(t, likelihood_ratio)

    def clear(self) -> None:
        """Forget all evidence (``clears``): the metric is the reference again."""
        self._pools = {self._rate: _Evidence(self._rate)}

    def log_odds(self, t: float) -> float:
        """The log-odds at time t (≥ the last firing)."""
        total = self._prior
        for pool in self._pools.values():
            total = pool.accumulate(total, t)
        return total

    def metric(self, t: float) -> float:
        """The property's probability at time t."""
        return _logistic(self.log_odds(t))

    @property
    def live_firings(self) -> int:
        """How many firings are kept on their own (the rest are folded or pruned)."""
        return sum(pool.live_firings for pool in self._pools.values())
