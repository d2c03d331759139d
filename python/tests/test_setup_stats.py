# The reviewer's analysis (orbed.study.setup_stats). Oracles: the signed-rank null distribution by
# enumeration of all 2^n sign patterns; hand-computed normal approximations (values in the comments);
# Holm's step-down by hand; a data set built so that pairing must matter; a mixed model recovering the
# effect its data were generated with.
import itertools

import numpy as np
import pytest

from helpers import joints_frame
from orbed.study import setup_stats


def enumerated_p(d):
    """Two-sided exact p of the signed-rank test: the share of the 2^n sign patterns of ranks 1..n
    whose W+ is at least as far from n(n+1)/4 as the data's."""
    n = len(d)
    ranks = np.argsort(np.argsort(np.abs(d))) + 1
    w = ranks[np.asarray(d) > 0].sum()
    mean = n * (n + 1) / 4
    count = sum(abs(sum(r for r, s in zip(range(1, n + 1), signs) if s) - mean) >= abs(w - mean)
                for signs in itertools.product((0, 1), repeat=n))
    return count / 2 ** n


def test_signed_rank_n6_exact_by_enumeration():
    a = np.array([11, 8, 13, 14, 15, 16.0])
    b = np.array([10, 10, 10, 10, 10, 10.0])  # differences 1, -2, 3, 4, 5, 6
    r = setup_stats.signed_rank(a, b)
    assert r["method"] == "exact" and r["n"] == 6
    assert (r["w_plus"], r["w_minus"]) == (19, 2)
    # W- = 2 or less: the subsets {}, {1}, {2} of the ranks; both tails: 2 * 3 / 64.
    assert r["p"] == pytest.approx(6 / 64) == enumerated_p(a - b)
    assert r["rank_biserial"] == pytest.approx((19 - 2) / 21)
    assert r["median_difference"] == 3.5
    lo, hi = r["median_difference_ci95"]
    assert lo <= 3.5 <= hi
    assert setup_stats.signed_rank(a, b)["median_difference_ci95"] == [lo, hi]  # seeded


def test_signed_rank_normal_approximation_with_a_zero():
    # x - y = -1 .. -8, +9 and one 0: the zero is dropped (n = 9), W+ = 9, W- = 36; mean 22.5,
    # sigma^2 = 9 * 10 * 19 / 24 = 71.25, z = (9 - 22.5 + 0.5) / sqrt(71.25) = -1.54011,
    # two-sided p = 2 Phi(-1.54011) = 0.1235 (table).
    x = [0, 0, 0, 0, 0, 0, 0, 0, 9, 3]
    y = [1, 2, 3, 4, 5, 6, 7, 8, 0, 3]
    r = setup_stats.signed_rank(x, y)
    assert r["method"] == "normal" and (r["n"], r["n_zero"]) == (9, 1)
    assert (r["w_plus"], r["w_minus"]) == (9, 36)
    assert r["p"] == pytest.approx(0.1235, abs=5e-4)
    # Differences {1, -1, 2, -3, -3}: |d| ranked 1.5, 1.5, 3, 4.5, 4.5, W+ = 4.5; tie-corrected
    # sigma^2 = 5 * 6 * 11 / 24 - (6 + 6) / 48 = 13.5, z = (4.5 - 7.5 + 0.5) / sqrt(13.5) = -0.68041,
    # two-sided p = 0.4962 (table: Phi(0.68) = 0.75175, Phi(0.69) = 0.75490).
    r = setup_stats.signed_rank([1, 0, 2, 0, 0], [0, 1, 0, 3, 3])
    assert r["w_plus"] == 4.5 and r["p"] == pytest.approx(0.4962, abs=1e-3)
    assert setup_stats.signed_rank([1, 2], [1, 2])["p"] is None  # no pair differs


def spread_study(factor, users=8, targets=3, seed=5):
    """Set-ups whose mean errors spread over two decades between set-ups; with fixed every joint of
    every set-up is `factor` times its error with ar (times a little noise)."""
    rng = np.random.default_rng(seed)
    setups = []
    for u in range(1, users + 1):
        for t in range(1, targets + 1):
            base = np.exp(rng.uniform(0, np.log(100))) * rng.uniform(0.5, 1.5, size=7)
            setups.append(("u%d" % u, "ar", t, list(base)))
            setups.append(("u%d" % u, "fixed", t, list(base * factor * rng.uniform(0.99, 1.01, size=7))))
    return joints_frame(setups)


def test_pairing_matters():
    joints = spread_study(factor=1.1)
    pooled = setup_stats.pooled(joints, "ar", "fixed")
    paired = setup_stats.by_setup(joints, "ar", "fixed")
    assert pooled["p"] > 0.3  # 10 % more error is lost in the spread between set-ups
    assert paired["p"] < 1e-4 and paired["n"] == 24
    assert paired["rank_biserial"] == -1  # every set-up's error is larger with fixed
    assert paired["median_difference_ci95"][1] < 0
    by_user = setup_stats.by_user(joints, "ar", "fixed")
    assert by_user["n"] == 8 and by_user["p"] == pytest.approx(2 / 256)  # exact: all 8 signs alike


def test_per_joint_holm_by_hand():
    joints = spread_study(factor=1.01)
    tests = setup_stats.per_joint(joints, "ar", "fixed")
    raw = [tests["joint%d" % j]["p"] for j in range(1, 8)]
    # Holm: sort ascending, multiply the k-th smallest by (m - k + 1), keep non-decreasing, cap at 1.
    order = np.argsort(raw)
    adjusted, running = [0.0] * 7, 0.0
    for k, i in enumerate(order):
        running = max(running, min(1.0, (7 - k) * raw[i]))
        adjusted[i] = running
    assert [tests["joint%d" % j]["p_holm"] for j in range(1, 8)] == pytest.approx(adjusted)
    assert all(tests["joint%d" % j]["n"] == 24 for j in range(1, 8))


def test_half_turns_and_start_target_relations():
    joints = joints_frame([("u1", "ar", 1, [170, 0, 0, 0, 0, 0, 95]), ("u1", "ar", 2, [1] * 7),
                           ("u1", "fixed", 1, [90, 0, 0, 0, 0, 0, 0]), ("u1", "fixed", 2, [0] * 7)])
    h = setup_stats.half_turns(joints)
    assert h["by_relation"] is None
    assert h["by_mode"]["ar"] == {"joints": 14, "half_turns": 2, "rate": pytest.approx(2 / 14), "setups": 2,
                                  "setups_with_half_turn": 1}
    assert h["by_mode"]["fixed"]["half_turns"] == 0  # 90 deg is not above 90
    # Bending joints 2, 4, 6 of target 20, -60, 40 deg: start (5, -5, 5) same, (-5, 5, -5) mirror.
    start = {1: [0, 5, 0, -5, 0, 5, 0], 2: [0, -5, 0, 5, 0, -5, 0]}
    joints["start_deg"] = [start[t][j - 1] if m == "ar" else (0 if j == 2 else start[1][j - 1])
                           for m, t, j in zip(joints["mode"], joints["target"], joints["joint"])]
    rel = setup_stats.relations(joints).set_index(["mode", "target"])["relation"]
    assert (rel[("ar", 1)], rel[("ar", 2)], rel[("fixed", 1)]) == ("same", "mirror", "mixed")
    by = setup_stats.half_turns(joints)["by_relation"]
    assert by["same"]["ar"]["half_turns"] == 2 and by["mirror"]["ar"]["half_turns"] == 0


def test_mixed_model_recovers_the_effect_it_was_generated_with():
    # ln error = 1 + 1.0 [fixed] + 0.5 [twisting] + user + target + noise: the fixed coefficient's
    # 95 % CI holds 1.0 and not 0, the interaction's holds 0; lognormal errors pick the log scale.
    rng = np.random.default_rng(11)
    user = {"u%d" % u: rng.normal(0, 0.3) for u in range(1, 13)}
    target = {t: rng.normal(0, 0.3) for t in (1, 2, 3)}
    setups = []
    for u in user:
        for t in target:
            for mode, effect in (("ar", 0.0), ("fixed", 1.0)):
                twisting = np.array([1, 0, 1, 0, 1, 0, 1])
                log_e = 1 + effect + 0.5 * twisting + user[u] + target[t] + rng.normal(0, 0.4, size=7)
                setups.append((u, mode, t, list(np.exp(log_e) - setup_stats.LOG_OFFSET_DEG)))
    m = setup_stats.mixed_model(joints_frame(setups))
    assert m["scale"].startswith("ln(")
    assert m["converged"] and m["n"] == 12 * 3 * 2 * 7 and m["users"] == 12 and m["targets"] == 3
    coef = {c["term"]: c for c in m["coefficients"]}
    fixed = coef["mode[T.fixed]"]
    assert fixed["ci95"][0] < 1.0 < fixed["ci95"][1] and fixed["ci95"][0] > 0
    assert coef["kind[T.twisting]"]["ci95"][0] < 0.5 < coef["kind[T.twisting]"]["ci95"][1]
    interaction = coef["mode[T.fixed]:kind[T.twisting]"]
    assert interaction["ci95"][0] < 0 < interaction["ci95"][1]
    assert fixed["ratio"] == pytest.approx(np.exp(fixed["estimate"]))
    assert set(m["variance_components"]) == {"user", "target"}


def test_per_target_pairs_users_on_each_target():
    joints = spread_study(factor=1.1, users=6, targets=2)
    per = setup_stats.per_target(joints)
    assert list(per) == ["1", "2"]
    assert per["1"]["paired"]["ar/fixed"]["n"] == 6
    assert per["1"]["paired"]["ar/fixed"]["p"] == pytest.approx(2 / 64)  # exact, all six alike
    assert per["2"]["modes"]["fixed"]["setups"] == 6
