"""The one bounded in-process cache (activeintent.memo)."""

from __future__ import annotations

import pytest

from activeintent.memo import BoundedCache, IdentityCache, memoized


def test_the_least_recently_used_entry_goes_first_and_is_seen_going():
    gone = []
    cache = BoundedCache(2, on_evict=gone.append)
    cache.put("a", 1)
    cache.put("b", 2)
    assert cache.get("a") == 1  # a is now the most recent
    cache.put("c", 3)
    assert "b" not in cache and "a" in cache and "c" in cache and len(cache) == 2
    assert gone == [2]
    cache.clear()
    assert len(cache) == 0 and sorted(gone) == [1, 2, 3]


def test_a_value_is_made_once_while_it_is_kept():
    made = []
    cache = BoundedCache(8)
    for _ in range(3):
        assert cache.get_or_make("k", lambda: made.append(1) or "v") == "v"
    assert made == [1]
    assert cache.get("absent", "default") == "default"
    with pytest.raises(ValueError, match="at least one"):
        BoundedCache(0)


def test_an_identity_cache_tells_equal_objects_apart_and_keeps_its_keys_alive():
    cache = IdentityCache(4)
    a, b = [1], [1]  # equal, not the same
    assert cache.get_or_make(a, lambda: "for a") == "for a"
    assert cache.get_or_make(b, lambda: "for b") == "for b"
    assert cache.get_or_make(a, lambda: "again") == "for a"
    # a dropped object cannot hand its entry to a new one that reuses its id: the entry keeps it
    for _ in range(100):
        assert cache.get_or_make(object(), lambda: "new") == "new"


def test_a_memoized_function_is_called_once_per_key_while_the_key_is_kept():
    calls = []

    @memoized(size=2, why="test: a pure function of x")
    def double(x):
        calls.append(x)
        return 2 * x

    assert [double(1), double(2), double(1)] == [2, 4, 2] and calls == [1, 2]
    double(3)  # over size: 2, the least recently used, goes; 1 was used after it
    assert double(1) == 2 and calls == [1, 2, 3]
    assert double(2) == 4 and calls == [1, 2, 3, 2]
    assert len(double.cache) == 2 and double.why.startswith("test") and double.__name__ == "double"


def test_memoized_keys_tell_arguments_apart():
    calls = []

    @memoized(size=8, why="test")
    def f(a, b=0):
        calls.append((a, b))
        return (a, b)

    @memoized(size=8, why="test")
    def none():
        calls.append("none")
        return None

    assert f(1) == (1, 0) and f(1, 2) == (1, 2) and f(2, 1) == (2, 1) and f(1, b=2) == (1, 2)
    assert f(1) == (1, 0) and f(1, 2) == (1, 2) and f(1, b=2) == (1, 2)
    assert calls == [(1, 0), (1, 2), (2, 1), (1, 2)]  # by keyword: an entry of its own
    assert none() is None and none() is None and calls.count("none") == 1  # a falsy result is kept too
    with pytest.raises(ValueError, match="wrong"):
        memoized(size=4, why=" ")
