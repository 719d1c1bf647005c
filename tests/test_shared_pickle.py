"""An object pickled once into shared memory comes back equal, its arrays
read-only, in this process and in workers, and its block is freed."""
import gc
from dataclasses import dataclass
from multiprocessing import shared_memory

import numpy as np
import pytest

from imgmtf.parallel import run_tasks
from imgmtf.shared_pickle import SharedPickle, load


@dataclass(frozen=True)
class Holder:
    name: str
    values: np.ndarray


def test_a_value_comes_back_equal_with_its_arrays_read_only_and_the_block_is_freed():
    rng = np.random.default_rng(1)
    value = [Holder("a", rng.normal(size=7)), Holder("b", np.arange(12, dtype=np.int32).reshape(3, 4)),
             {"fortran": np.asfortranarray(rng.normal(size=(3, 5))), "strided": np.arange(10.0)[::3],
              "empty": np.zeros(0), "text": "é", "none": None}]
    with SharedPickle(value) as shared:
        loaded = load(shared.name)
        assert load(shared.name) is loaded                  # loaded once per process
        assert [h.name for h in loaded[:2]] == ["a", "b"]
        for given, back in [(value[0].values, loaded[0].values), (value[1].values, loaded[1].values),
                            *((value[2][k], loaded[2][k]) for k in ("fortran", "strided", "empty"))]:
            assert back.dtype == given.dtype and np.array_equal(back, given)
        assert not loaded[0].values.flags.writeable
        assert loaded[2]["text"] == "é" and loaded[2]["none"] is None
    with pytest.raises(FileNotFoundError):
        shared_memory.SharedMemory(name=shared.name)


def total_of(task):
    name, index = task
    return float(load(name)[index].sum()), gc.get_freeze_count() > 0


def test_workers_load_it_by_name_and_keep_it_out_of_the_collectors_passes():
    value = [np.full(100, k, float) for k in range(4)]
    with SharedPickle(value) as shared:
        results = list(run_tasks(total_of, [(shared.name, k) for k in range(4)], workers=2))
    assert results == [(0, True), (100, True), (200, True), (300, True)]
