"""The asks' protocol: generators advanced in lockstep, each round's asks of a name answered by one call."""
import pytest

from imgmtf.errors import UnsuitableTargetError
from imgmtf.estimate import asks
from imgmtf.estimate.asks import Ask, alone, drive


@pytest.fixture
def doubling(monkeypatch):
    """A registered ask that doubles each payload (a negative one fails), recording each call's batch."""
    calls = []

    def double(payloads):
        calls.append(list(payloads))
        return [UnsuitableTargetError("negative") if p < 0 else 2 * p for p in payloads]
    monkeypatch.setitem(asks.ANSWERS, "double", double)
    return calls


def _twice(x, fail_early=False):
    if fail_early:
        raise ValueError("refused before asking")
    first = yield Ask("double", x)
    try:
        second = yield Ask("double", first - 100 if x == 3 else first)
    except UnsuitableTargetError:
        return "caught where asked"
    return second


def test_drive_answers_each_round_in_one_call_and_exceptions_in_place(doubling):
    out = drive([_twice(1), _twice(2, fail_early=True), _twice(3), _twice(-1)])
    assert out[0] == 4
    assert isinstance(out[1], ValueError)
    assert out[2] == "caught where asked"          # the answer's exception raised where the chip asked
    assert isinstance(out[3], UnsuitableTargetError)
    assert doubling == [[1, 3, -1], [2, -94]]      # two rounds, one call each


def test_alone_is_a_batch_of_one_and_raises(doubling):
    assert alone(_twice(5)) == 20
    assert doubling == [[5], [10]]
    with pytest.raises(UnsuitableTargetError):
        alone(_twice(-2))
