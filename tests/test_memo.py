"""The one bounded in-process cache (activeintent.memo)."""

from __future__ import annotations

import pytest

from activeintent.memo import BoundedCache, IdentityCache


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
