"""Agreement between two ways of measuring the same thing (the kiosk and a clinician): numbers in,
numbers out, no database and no web stack, so every figure a validation study shows can be checked
against published worked examples (tests/station/test_agreement.py).

* :func:`weighted_kappa`: Cohen's (1968) weighted kappa of two ratings on ordered categories, with
  quadratic (Fleiss-Cohen) weights by default, and its large-sample standard error (Fleiss, Cohen &
  Everitt 1969, the non-null variance; what SAS PROC FREQ's AGREE prints as ASE); the interval is
  kappa ± z·SE, kept within [−1, 1].
* :func:`icc_2_1`: ICC(2,1), two-way random effects, absolute agreement, single measures (Shrout &
  Fleiss 1979 case 2; McGraw & Wong 1996 ICC(A,1)), with the F-distribution interval of McGraw &
  Wong 1996 (Satterthwaite's degrees of freedom for the denominator).
* :func:`bland_altman`: bias and 95 % limits of agreement of the differences, with intervals as
  Bland & Altman 1999 §2.3 give them: SE(bias) = s/√n, SE(limit) = s·√(1/n + z²/(2(n−1))), both
  with Student's t on n−1 degrees of freedom (their 1986 paper rounded the latter to √(3s²/n)).

The F and t quantiles are computed here (the regularised incomplete beta by its continued fraction,
Numerical Recipes §6.4, inverted by bisection): scipy is not among the station's dependencies.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from statistics import NormalDist

from basis import record

#: the confidence of every interval (two-sided)
CONFIDENCE = 0.95


class AgreementError(ValueError):
    """The numbers cannot give this statistic (message says which and why)."""


@record
class Estimate:
    """A statistic and its two-sided :data:`CONFIDENCE` interval."""

    value: float
    low: float
    high: float
    #: the standard error the interval was built from (None where it is not symmetric: the ICC)
    se: float | None = None


@record
class Icc:
    """ICC(2,1) with its interval, and the analysis of variance it came from."""

    estimate: Estimate
    #: subjects and raters (methods)
    n: int
    k: int
    #: the F test of subjects (MSR / MSE) and its degrees of freedom
    f: float
    df1: int
    df2: int


@record
class BlandAltman:
    """Bias (mean of first − second) and the limits of agreement, each with its interval."""

    n: int
    sd: float
    bias: Estimate
    lower: Estimate
    upper: Estimate


# -- distributions ------------------------------------------------------------------------------


def _beta_fraction(a: float, b: float, x: float) -> float:
    """The continued fraction of the incomplete beta (modified Lentz; Numerical Recipes §6.4)."""
    tiny, c, d = 1e-300, 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 10_000):
        for numerator in (
            m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1)),
        ):
            d = 1.0 + numerator * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + numerator / c
            c = c if abs(c) > tiny else tiny
            h *= d * c
        if abs(d * c - 1.0) < 1e-15:
            return h
    raise ArithmeticError(f"the incomplete beta ({a}, {b}, {x}) did not converge")


def beta_cdf(x: float, a: float, b: float) -> float:
    """The regularised incomplete beta I_x(a, b): the Beta(a, b) distribution function."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    log_front = math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _beta_fraction(a, b, x) / a
    return 1.0 - math.exp(log_front) * _beta_fraction(b, a, 1.0 - x) / b


def _beta_quantile(p: float, a: float, b: float) -> float:
    """The x with I_x(a, b) = p, by bisection (the cdf is monotone; 200 halvings reach the float
    resolution whatever the shape)."""
    low, high = 0.0, 1.0
    for _ in range(200):
        middle = (low + high) / 2.0
        if beta_cdf(middle, a, b) < p:
            low = middle
        else:
            high = middle
        if high - low <= 1e-16 * max(high, 1e-300):
            break
    return (low + high) / 2.0


def f_quantile(p: float, d1: float, d2: float) -> float:
    """The p quantile of Snedecor's F(d1, d2) (real degrees of freedom allowed)."""
    if not 0.0 < p < 1.0 or d1 <= 0 or d2 <= 0:
        raise AgreementError(f"no F quantile for p={p}, d1={d1}, d2={d2}")
    y = _beta_quantile(p, d1 / 2.0, d2 / 2.0)
    return d2 * y / (d1 * (1.0 - y))


def t_quantile(p: float, df: float) -> float:
    """The p quantile of Student's t on ``df`` degrees of freedom (t² on df is F(1, df))."""
    if not 0.0 < p < 1.0 or df <= 0:
        raise AgreementError(f"no t quantile for p={p}, df={df}")
    if p == 0.5:
        return 0.0
    t = math.sqrt(f_quantile(abs(2.0 * p - 1.0), 1.0, df))
    return t if p > 0.5 else -t


def _z() -> float:
    return NormalDist().inv_cdf(0.5 + CONFIDENCE / 2.0)


# -- weighted kappa -----------------------------------------------------------------------------


def agreement_weights(k: int, kind: str = "quadratic") -> list[list[float]]:
    """Agreement weights for ``k`` ordered categories: 1 on the diagonal, falling to 0 at the far
    corners, with the squared distance (``quadratic``, Fleiss-Cohen) or the distance (``linear``,
    Cicchetti-Allison)."""
    if k < 2:
        raise AgreementError("weighted kappa needs at least two categories")
    power = {"quadratic": 2, "linear": 1}.get(kind)
    if power is None:
        raise AgreementError(f"unknown weights {kind!r}: quadratic or linear")
    return [[1.0 - (abs(i - j) / (k - 1)) ** power for j in range(k)] for i in range(k)]


def table_of(pairs: Sequence[tuple[int, int]], k: int) -> list[list[int]]:
    """The k×k table of counts of ``pairs`` (first rating's category 1..k in rows)."""
    table = [[0] * k for _ in range(k)]
    for first, second in pairs:
        if not (1 <= first <= k and 1 <= second <= k):
            raise AgreementError(f"a rating ({first}, {second}) is outside the categories 1 to {k}")
        table[first - 1][second - 1] += 1
    return table


def weighted_kappa(table: Sequence[Sequence[float]], weights: str = "quadratic") -> Estimate:
    """Weighted kappa of a square table of counts (rows: the first rating, columns: the second),
    categories in their order; the interval is kappa ± z·SE with the Fleiss-Cohen-Everitt (1969)
    large-sample SE, kept within kappa's range [-1, 1]. AgreementError when it is not defined or
    tells nothing (fewer than 2 ratings; one side, or both, always in one category)."""
    k = len(table)
    if any(len(row) != k for row in table):
        raise AgreementError("the table of ratings must be square")
    w = agreement_weights(k, weights)
    n = float(sum(sum(row) for row in table))
    if n < 2:
        raise AgreementError("weighted kappa needs at least two pairs of ratings")
    p = [[cell / n for cell in row] for row in table]
    rows = [sum(row) for row in p]
    cols = [sum(p[i][j] for i in range(k)) for j in range(k)]
    observed = sum(w[i][j] * p[i][j] for i in range(k) for j in range(k))
    chance = sum(w[i][j] * rows[i] * cols[j] for i in range(k) for j in range(k))
    if chance >= 1.0 - 1e-12:
        raise AgreementError("weighted kappa is not defined: every rating on both sides is in the same category")
    if sum(1 for r in rows if r > 0) == 1 or sum(1 for c in cols if c > 0) == 1:
        # kappa is 0 by construction and its standard error 0: no interval to give
        raise AgreementError("weighted kappa says nothing here: one side gave every patient the same answer")
    kappa = (observed - chance) / (1.0 - chance)
    w_row = [sum(cols[j] * w[i][j] for j in range(k)) for i in range(k)]  # w̄_i.
    w_col = [sum(rows[i] * w[i][j] for i in range(k)) for j in range(k)]  # w̄_.j
    spread = sum(p[i][j] * (w[i][j] - (w_row[i] + w_col[j]) * (1.0 - kappa)) ** 2 for i in range(k) for j in range(k))
    variance = max(spread - (kappa - chance * (1.0 - kappa)) ** 2, 0.0) / (n * (1.0 - chance) ** 2)
    se = math.sqrt(variance)
    return Estimate(kappa, max(kappa - _z() * se, -1.0), min(kappa + _z() * se, 1.0), se)


# -- ICC(2,1) -----------------------------------------------------------------------------------


def icc_2_1(ratings: Sequence[Sequence[float]]) -> Icc:
    """ICC(2,1) of ``ratings`` (one row per subject, one column per rater or method, no gaps),
    with McGraw & Wong's (1996) F-distribution interval. AgreementError for fewer than 2
    subjects or raters, or ratings with no variation at all."""
    n = len(ratings)
    k = len(ratings[0]) if n else 0
    if n < 2 or k < 2 or any(len(row) != k for row in ratings):
        raise AgreementError("ICC(2,1) needs at least two subjects, each rated by the same two or more raters")
    grand = sum(sum(row) for row in ratings) / (n * k)
    row_means = [sum(row) / k for row in ratings]
    col_means = [sum(row[j] for row in ratings) / n for j in range(k)]
    ss_rows = k * sum((m - grand) ** 2 for m in row_means)
    ss_cols = n * sum((m - grand) ** 2 for m in col_means)
    ss_total = sum((x - grand) ** 2 for row in ratings for x in row)
    ss_error = max(ss_total - ss_rows - ss_cols, 0.0)
    msr, msc = ss_rows / (n - 1), ss_cols / (k - 1)
    mse = ss_error / ((n - 1) * (k - 1))
    denominator = msr + (k - 1) * mse + k * (msc - mse) / n
    if denominator <= 0 or mse <= 0 and msr <= 0:
        raise AgreementError("ICC(2,1) is not defined: the ratings do not vary")
    icc = (msr - mse) / denominator
    df1, df2 = n - 1, (n - 1) * (k - 1)
    f = msr / mse if mse > 0 else math.inf
    low, high = _icc_interval(icc, n, k, msr, msc, mse)
    return Icc(Estimate(icc, low, high), n, k, f, df1, df2)


def _icc_interval(icc: float, n: int, k: int, msr: float, msc: float, mse: float) -> tuple[float, float]:
    """McGraw & Wong (1996), case 2A (absolute agreement, single measures)."""
    if mse <= 0:  # perfect agreement: nothing left to be unsure of
        return icc, icc
    a = k * icc / (n * (1.0 - icc))
    b = 1.0 + k * icc * (n - 1) / (n * (1.0 - icc))
    v = (a * msc + b * mse) ** 2 / ((a * msc) ** 2 / (k - 1) + (b * mse) ** 2 / ((n - 1) * (k - 1)))
    tail = 0.5 + CONFIDENCE / 2.0
    f_upper, f_lower = f_quantile(tail, n - 1, v), f_quantile(tail, v, n - 1)
    spread = k * msc + (k * n - k - n) * mse
    low = n * (msr - f_upper * mse) / (f_upper * spread + n * msr)
    high = n * (f_lower * msr - mse) / (spread + n * f_lower * msr)
    return low, high


# -- Bland-Altman -------------------------------------------------------------------------------


def bland_altman(first: Sequence[float], second: Sequence[float], z: float | None = None) -> BlandAltman:
    """Bias (mean of first − second) and limits bias ± z·s (z: the normal quantile of
    :data:`CONFIDENCE`, 1.96), each with a t interval on n−1 degrees of freedom (Bland & Altman
    1999). AgreementError for fewer than 3 pairs or lists of different lengths."""
    if len(first) != len(second):
        raise AgreementError("the two lists of totals differ in length")
    n = len(first)
    if n < 3:
        raise AgreementError("limits of agreement need at least three pairs of totals")
    z = _z() if z is None else z
    differences = [a - b for a, b in zip(first, second, strict=True)]
    bias = sum(differences) / n
    sd = math.sqrt(sum((d - bias) ** 2 for d in differences) / (n - 1))
    t = t_quantile(0.5 + CONFIDENCE / 2.0, n - 1)
    se_bias = sd / math.sqrt(n)
    se_limit = sd * math.sqrt(1.0 / n + z**2 / (2.0 * (n - 1)))

    def around(value: float, se: float) -> Estimate:
        return Estimate(value, value - t * se, value + t * se, se)

    return BlandAltman(n, sd, around(bias, se_bias), around(bias - z * sd, se_limit), around(bias + z * sd, se_limit))
