"""The validation study's statistics (:mod:`station.agreement`) against published worked examples:
each case names where its data and figures were printed, and asserts to the precision printed."""

from __future__ import annotations

import pytest

from station.agreement import (
    AgreementError,
    agreement_weights,
    bland_altman,
    f_quantile,
    icc_2_1,
    t_quantile,
    table_of,
    weighted_kappa,
)

#: Shrout & Fleiss (1979), Table 2: 6 targets rated by 4 judges
SHROUT_FLEISS = [[9, 2, 5, 8], [6, 1, 3, 2], [8, 4, 6, 8], [7, 1, 2, 6], [10, 5, 6, 9], [6, 2, 4, 7]]
#: Bland & Altman (1986, Lancet), Table 1: first PEFR reading (l/min) by the Wright and the mini
#: Wright meter, 17 subjects
WRIGHT = [494, 395, 516, 434, 476, 557, 413, 442, 650, 433, 417, 656, 267, 478, 178, 423, 427]
MINI_WRIGHT = [512, 430, 520, 428, 500, 600, 364, 380, 658, 445, 432, 626, 260, 477, 259, 350, 451]
#: R package irr, data set ``anxiety`` (20 subjects rated by 3 raters on 1-6), raters 2 and 3
ANXIETY_2 = [3, 6, 4, 6, 2, 4, 2, 4, 3, 3, 2, 3, 3, 3, 2, 2, 1, 3, 3, 4]
ANXIETY_3 = [2, 1, 4, 4, 3, 2, 1, 6, 1, 1, 1, 2, 3, 3, 1, 1, 3, 3, 2, 2]


def test_icc_2_1_of_shrout_and_fleiss_table_2() -> None:
    """Shrout & Fleiss (1979) print ICC(2,1) = .29 for their Table 2; R psych::ICC prints its
    McGraw & Wong interval as 0.019 to 0.76, with F = 11.0 on 5 and 15 degrees of freedom."""
    found = icc_2_1(SHROUT_FLEISS)
    assert round(found.estimate.value, 2) == 0.29
    assert round(found.estimate.low, 3) == 0.019 and round(found.estimate.high, 2) == 0.76
    assert (round(found.f, 1), found.df1, found.df2, found.n, found.k) == (11.0, 5, 15, 6, 4)


def test_icc_of_perfect_agreement_is_one_and_of_too_few_subjects_is_refused() -> None:
    perfect = icc_2_1([[10, 10], [55, 55], [90, 90]])
    assert (perfect.estimate.value, perfect.estimate.low, perfect.estimate.high) == (1.0, 1.0, 1.0)
    with pytest.raises(AgreementError, match="at least two subjects"):
        icc_2_1([[1, 2]])
    with pytest.raises(AgreementError, match="do not vary"):
        icc_2_1([[5, 5], [5, 5]])


def test_weighted_kappa_with_linear_weights_as_sas_prints_it() -> None:
    """SAS/STAT PROC FREQ (AGREE), the 3x3 table below with scores 0, 1, 2 (Cicchetti-Allison
    weights): weighted kappa 0.4701, ASE 0.1457, 95 % limits 0.1845 and 0.7558 (the printout
    statsmodels' test_inter_rater.py checks against)."""
    found = weighted_kappa([[0, 4, 1], [0, 8, 0], [0, 1, 5]], weights="linear")
    assert [round(x, 4) for x in (found.value, found.se, found.low, found.high)] == [0.4701, 0.1457, 0.1845, 0.7558]


def test_weighted_kappa_with_quadratic_weights_as_r_irr_prints_it() -> None:
    """R irr::kappa2(anxiety[, 2:3], "squared") = 0.2520325 and "equal" = 0.1459075; irr ranks the
    categories present (1, 2, 3, 4, 6), so the table here does the same."""
    levels = sorted(set(ANXIETY_2) | set(ANXIETY_3))
    rank = {level: n for n, level in enumerate(levels, 1)}
    table = table_of([(rank[a], rank[b]) for a, b in zip(ANXIETY_2, ANXIETY_3, strict=True)], len(levels))
    assert round(weighted_kappa(table).value, 7) == 0.2520325
    assert round(weighted_kappa(table, weights="linear").value, 7) == 0.1459075


def test_quadratic_weights_and_the_undefined_cases() -> None:
    assert agreement_weights(3) == [[1.0, 0.75, 0.0], [0.75, 1.0, 0.75], [0.0, 0.75, 1.0]]
    assert weighted_kappa(table_of([(1, 1), (2, 2), (3, 3)], 3)).value == pytest.approx(1.0)
    with pytest.raises(AgreementError, match="same category"):
        weighted_kappa(table_of([(2, 2), (2, 2), (2, 2)], 3))
    with pytest.raises(AgreementError, match="one side gave every patient the same answer"):
        weighted_kappa(table_of([(1, 2), (2, 2), (3, 2)], 3))
    wide = weighted_kappa(table_of([(1, 1), (2, 2), (3, 3), (3, 2)], 3))  # few pairs: a wide interval
    assert wide.high == 1.0 and wide.value + 1.959964 * wide.se > 1.0  # kept within kappa's range
    with pytest.raises(AgreementError, match="at least two pairs"):
        weighted_kappa(table_of([(2, 2)], 3))
    with pytest.raises(AgreementError, match="outside the categories 1 to 3"):
        table_of([(4, 1)], 3)


def test_bland_altman_of_the_pefr_data() -> None:
    """Bland & Altman (1986): mean difference −2.1, SD 38.8 l/min; their limits, d̄ ± 2s, −79.7 to
    75.5. With 1.96 the limits are −78.1 and 73.9. The intervals are Bland & Altman's (1999):
    the bias's SE s/√n, a limit's s·√(1/n + z²/(2(n−1))), t on 16 degrees of freedom (2.1199)."""
    found = bland_altman(WRIGHT, MINI_WRIGHT)
    assert (found.n, round(found.bias.value, 1), round(found.sd, 1)) == (17, -2.1, 38.8)
    assert (round(found.lower.value, 1), round(found.upper.value, 1)) == (-78.1, 73.9)
    s, n, t = found.sd, 17, 2.1199053
    assert found.bias.se == pytest.approx(s / n**0.5)
    assert found.lower.se == pytest.approx(s * (1 / n + 1.959964**2 / (2 * (n - 1))) ** 0.5)
    assert found.lower.low == pytest.approx(found.lower.value - t * found.lower.se)
    assert found.upper.high == pytest.approx(found.upper.value + t * found.upper.se)
    as_in_1986 = bland_altman(WRIGHT, MINI_WRIGHT, z=2.0)  # the paper rounded d̄ and s first: −2.1 ± 77.6
    assert (round(as_in_1986.lower.value, 1), round(as_in_1986.upper.value, 1)) == (-79.6, 75.4)
    assert (round(-2.1 - 2 * 38.8, 1), round(-2.1 + 2 * 38.8, 1)) == (-79.7, 75.5)


def test_the_1986_interval_of_the_lower_limit_with_its_rounder_standard_error() -> None:
    """Bland & Altman (1986) give the lower limit's 95 % interval as −114.3 to −45.1, from
    SE = √(3s²/n) and t(16) = 2.12: the quantile and the arithmetic reproduce it."""
    found = bland_altman(WRIGHT, MINI_WRIGHT, z=2.0)
    se_1986 = (3 * 38.8**2 / 17) ** 0.5
    t = t_quantile(0.975, 16)
    assert (round(-79.7 - t * se_1986, 1), round(-79.7 + t * se_1986, 1)) == (-114.3, -45.1)
    assert found.lower.se > se_1986 * 0.98  # the exact form is close to, not below, the rounder one
    with pytest.raises(AgreementError, match="at least three pairs"):
        bland_altman([1, 2], [1, 2])


@pytest.mark.parametrize(
    ("p", "d1", "d2", "table"),
    [
        # printed F tables (upper 5 % and 2.5 % points), and t via F(1, df)
        (0.95, 1, 10, 4.96),
        (0.95, 3, 15, 3.29),
        (0.975, 5, 15, 3.58),
        (0.95, 10, 20, 2.35),
        (0.99, 4, 30, 4.02),
    ],
)
def test_f_quantiles_against_printed_tables(p: float, d1: int, d2: int, table: float) -> None:
    assert round(f_quantile(p, d1, d2), 2) == table


def test_t_quantiles_and_real_degrees_of_freedom() -> None:
    assert round(t_quantile(0.975, 1), 3) == 12.706
    assert round(t_quantile(0.975, 9), 3) == 2.262
    assert round(t_quantile(0.975, 30), 3) == 2.042
    assert t_quantile(0.025, 9) == pytest.approx(-t_quantile(0.975, 9))
    # a real-valued df (the ICC interval's Satterthwaite df) lies between its integer neighbours
    assert f_quantile(0.975, 5, 15) > f_quantile(0.975, 5, 15.5) > f_quantile(0.975, 5, 16)
    with pytest.raises(AgreementError):
        f_quantile(1.0, 2, 3)


def test_f_quantiles_against_scipy_where_it_is_installed() -> None:
    """scipy is not a station dependency; the dev environment has it (through scikit-image)."""
    stats = pytest.importorskip("scipy.stats")
    for p in (0.025, 0.5, 0.975, 0.999):
        for d1, d2 in ((1, 1), (1, 16), (5, 15), (2.7, 41.3), (30, 3), (200, 200)):
            assert f_quantile(p, d1, d2) == pytest.approx(stats.f.ppf(p, d1, d2), rel=1e-9)
