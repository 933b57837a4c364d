"""The swept-cell tables' on-disk cache: what a later process loads equals a fresh build, and a corrupt,
truncated, foreign or unwritable cache falls back to building them, silently."""

import numpy as np
import pytest

from htetro_opt import _cache
from htetro_opt.model import sweeps
from htetro_opt.model.sweeps import _FIELDS, _build_sweep_tables, _sweep_tables, sweep_tables

CLEARANCE = 0.25  # not the default: its entry is this test's own


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty cache folder of the test's own, and no table of this process's memory."""
    monkeypatch.setenv(_cache.ENV, str(tmp_path / "cache"))
    _sweep_tables.cache_clear()
    yield tmp_path / "cache"
    _sweep_tables.cache_clear()


@pytest.fixture(scope="module")
def fresh():
    return _build_sweep_tables(CLEARANCE)


def builds(monkeypatch):
    """A list that gets one entry per table build."""
    calls = []

    def counted(clearance):
        calls.append(clearance)
        return _build_sweep_tables(clearance)

    monkeypatch.setattr(sweeps, "_build_sweep_tables", counted)
    return calls


def assert_same(tables, fresh):
    assert tables.clearance == fresh.clearance
    for field in _FIELDS:
        got, want = getattr(tables, field), getattr(fresh, field)
        assert got.dtype == want.dtype and got.shape == want.shape, field
        assert np.array_equal(got, want), field
        assert not got.flags.writeable, field


def entries(folder):
    return sorted(folder.glob("sweeps-*.npz"))


def test_a_second_process_loads_the_tables_without_building_them(cache, monkeypatch, fresh):
    calls = builds(monkeypatch)
    assert_same(sweep_tables(CLEARANCE), fresh)
    assert calls == [CLEARANCE] and len(entries(cache)) == 1
    assert not list(cache.glob("*.tmp"))  # written beside, renamed into place
    _sweep_tables.cache_clear()  # as a new process: nothing in memory, the file on disk
    loaded = sweep_tables(CLEARANCE)
    assert calls == [CLEARANCE]  # loaded, not built
    assert_same(loaded, fresh)


def test_another_clearance_or_source_is_another_entry(cache, monkeypatch):
    sweep_tables(CLEARANCE)
    sweep_tables(CLEARANCE + 0.25)
    assert len(entries(cache)) == 2
    _sweep_tables.cache_clear()
    monkeypatch.setattr(sweeps, "_SOURCES", sweeps._SOURCES + (_cache.__file__,))  # as an edit of the model
    calls = builds(monkeypatch)
    sweep_tables(CLEARANCE)
    assert calls == [CLEARANCE] and len(entries(cache)) == 3


@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty", "foreign"])
def test_a_damaged_entry_is_rebuilt_and_replaced(cache, monkeypatch, fresh, damage):
    sweep_tables(CLEARANCE)
    (path,) = entries(cache)
    data = path.read_bytes()
    if damage == "garbage":
        path.write_bytes(b"not a zip file" * 100)
    elif damage == "truncated":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "empty":
        path.write_bytes(b"")
    else:  # a readable file of another layout: a table of the wrong shape
        np.savez(path, **{field: np.zeros(3, dtype=np.int64) for field in _FIELDS})
    _sweep_tables.cache_clear()
    calls = builds(monkeypatch)
    assert_same(sweep_tables(CLEARANCE), fresh)
    assert calls == [CLEARANCE]
    _sweep_tables.cache_clear()  # the rebuilt entry replaced the damaged one
    assert_same(sweep_tables(CLEARANCE), fresh)
    assert calls == [CLEARANCE]


def test_an_unwritable_or_disabled_cache_builds_every_time(tmp_path, monkeypatch, fresh):
    blocker = tmp_path / "a-file"
    blocker.write_text("in the way of the folder")
    for setting in (str(blocker / "cache"), "off"):
        monkeypatch.setenv(_cache.ENV, setting)
        _sweep_tables.cache_clear()
        calls = builds(monkeypatch)
        for _ in range(2):
            _sweep_tables.cache_clear()
            assert_same(sweep_tables(CLEARANCE), fresh)
        assert calls == [CLEARANCE, CLEARANCE]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]
    _sweep_tables.cache_clear()


def test_the_default_folder_is_the_users_cache(monkeypatch, tmp_path):
    monkeypatch.delenv(_cache.ENV, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    if _cache.sys.platform not in ("win32", "darwin"):
        assert _cache.cache_dir() == tmp_path / "htetro-opt"
    monkeypatch.setenv(_cache.ENV, "")
    assert _cache.cache_dir() is None
