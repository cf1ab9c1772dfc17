"""The paired comparison of agents.evaluate on returns and on a final metric."""
from agents.evaluate import compare


def _episodes(returns, impulses):
    return [dict(ret=r, final={"impulse_per_metre": j}) for r, j in zip(returns, impulses)]


def test_lower_metric_is_better_by_two_standard_errors():
    policy = _episodes([10, 11, 12, 13], [1.0, 1.1, 0.9, 1.0])
    baseline = _episodes([10, 10, 10, 10], [2.0, 2.2, 1.8, 2.1])
    c = compare(policy, baseline, "impulse_per_metre", lower_is_better=True)
    assert c["diff"] < 0 and c["beats"]
    # the same numbers read the other way round do not beat
    assert not compare(policy, baseline, "impulse_per_metre")["beats"]
    assert compare(policy, baseline)["beats"]                 # returns: +1.5 ± 0.65


def test_a_difference_within_two_standard_errors_does_not_beat():
    policy = _episodes([10, 12, 8, 11], [1, 1, 1, 1])
    baseline = _episodes([11, 10, 10, 9], [1, 1, 1, 1])
    c = compare(policy, baseline)
    assert c["diff"] == 0.25 and not c["beats"]
