"""The one in-process cache of the library: a bounded map, least recently used out first.

Every cache says where it is made what its key is, how many entries it keeps and what would
make an entry wrong (for a pure function of its key: nothing, so eviction changes speed only,
never a result). Disk caches (model responses, hypothesis spaces) are not these.
"""

from __future__ import annotations

import functools
import inspect
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Generic, ParamSpec, TypeVar

K = TypeVar("K", bound=Hashable)
V = TypeVar("V")
P = ParamSpec("P")


class BoundedCache(Generic[K, V]):
    """At most ``size`` entries; a hit makes an entry the most recent, an insert beyond
    ``size`` drops the least recent (``on_evict`` sees its value, e.g. to close it)."""

    def __init__(self, size: int, on_evict: Callable[[V], None] | None = None):
        if size < 1:
            raise ValueError(f"a cache keeps at least one entry, got size={size}")
        self.size = size
        self._on_evict = on_evict
        self._data: OrderedDict[K, V] = OrderedDict()

    def get(self, key: K, default: V | None = None) -> V | None:
        try:
            value = self._data[key]
        except KeyError:
            return default
        self._data.move_to_end(key)
        return value

    def put(self, key: K, value: V) -> V:
        self._data[key] = value
        self._data.move_to_end(key)
        while len(self._data) > self.size:
            _, old = self._data.popitem(last=False)
            if self._on_evict is not None:
                self._on_evict(old)
        return value

    def get_or_make(self, key: K, make: Callable[[], V]) -> V:
        """The cached value of ``key``, made (and kept) when absent."""
        try:
            value = self._data[key]
        except KeyError:
            return self.put(key, make())
        self._data.move_to_end(key)
        return value

    def clear(self) -> None:
        while self._data:
            _, old = self._data.popitem(last=False)
            if self._on_evict is not None:
                self._on_evict(old)

    def __contains__(self, key: object) -> bool:
        return key in self._data

    def __len__(self) -> int:
        return len(self._data)


class IdentityCache(Generic[V]):
    """Values per *object* (not per equal value): keyed by ``id(obj)``, the object kept with its
    value so that its id cannot be reused by another object while the entry lives."""

    def __init__(self, size: int):
        self._cache: BoundedCache[int, tuple[object, V]] = BoundedCache(size)

    def get_or_make(self, obj: object, make: Callable[[], V]) -> V:
        hit = self._cache.get(id(obj))
        if hit is not None and hit[0] is obj:
            return hit[1]
        return self._cache.put(id(obj), (obj, make()))[1]

    def clear(self) -> None:
        self._cache.clear()

    def __len__(self) -> int:
        return len(self._cache)


_KEYWORDS = object()  # separates positional from keyword arguments in a key


def memoized(size: int, why: str) -> Callable[[Callable[P, V]], Callable[P, V]]:
    """Decorator: keep a pure function's results in a :class:`BoundedCache` of ``size`` entries.

    Key: the call's arguments (hashable; equal arguments share an entry, so ``f(1)`` and
    ``f(1.0)`` do; the same value passed by keyword is another entry). ``why`` says what the
    key stands for and what would make an entry wrong (for a pure function of its arguments:
    nothing, so eviction changes speed only, never a result); it is the wrapper's ``why``. The
    wrapper's ``cache`` is the BoundedCache (``cache.clear()`` empties it). A function of one
    parameter is keyed by its argument itself and called with it positionally (the hot
    helpers: as fast as functools.cache).
    """
    if not why.strip():
        raise ValueError("say what the key is and what would make an entry wrong")

    def wrap(func: Callable[P, V]) -> Callable[P, V]:
        cache: BoundedCache = BoundedCache(size)
        data, put = cache._data, cache.put
        params = list(inspect.signature(func).parameters.values())
        single = len(params) == 1 and params[0].kind in (inspect.Parameter.POSITIONAL_ONLY,
                                                         inspect.Parameter.POSITIONAL_OR_KEYWORD)

        if single:
            @functools.wraps(func)
            def one(arg):  # type: ignore[no-untyped-def]
                try:
                    value = data[arg]
                except KeyError:
                    return put(arg, func(arg))
                try:
                    data.move_to_end(arg)
                except KeyError:  # evicted meanwhile by another thread: still the right value
                    pass
                return value

            wrapper = one
        else:
            @functools.wraps(func)
            def many(*args, **kwargs):  # type: ignore[no-untyped-def]
                key = (*args, _KEYWORDS, *kwargs.items()) if kwargs else args
                try:
                    value = data[key]
                except KeyError:
                    return put(key, func(*args, **kwargs))
                try:
                    data.move_to_end(key)
                except KeyError:
                    pass
                return value

            wrapper = many
        wrapper.cache = cache  # type: ignore[attr-defined]
        wrapper.why = why  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return wrap
