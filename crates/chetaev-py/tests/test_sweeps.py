"""Sweeps of a scene from Python (docs/sweeps.md): the paper's scene over grids and random samples,
against the closed forms; shards joined into the whole; bad specifications refused."""

from __future__ import annotations

import math
import pathlib

import numpy as np
import pytest

import chetaev

# tests -> chetaev-py -> crates -> the repository
SCENES = pathlib.Path(__file__).resolve().parents[3] / "scenes"


def impact_time(v0, h0, g=10.0):
    """T = (v0/g) arccosh exp(g h0/v0²), (42.32)."""
    return v0 / g * math.acosh(math.exp(g * h0 / v0**2))


def impact_range(v0, h0, g=10.0):
    """R = (v0²/g) arccos exp(−g h0/v0²)."""
    return v0**2 / g * math.acos(math.exp(-g * h0 / v0**2))


@pytest.fixture(scope="module")
def scene():
    return chetaev.Scene.load(SCENES / "uniform-projectile.toml")


def test_a_grid_gives_the_closed_form_impact_of_every_point(scene):
    table = scene.sweep(
        {"v0": {"from": 5.0, "to": 20.0, "count": 4}, "h0": [1.0, 5.0, 20.0]},
        collect=["impact.t", "impact.x", "max_abs.mu_1"],
        jobs=2,
    )
    assert len(table) == 12
    assert table.variables == ["v0", "h0"]
    assert table.columns == ["impact.t", "impact.x", "max_abs.mu_1"]
    assert table.values.shape == (12, 2) and table.quantities.shape == (12, 3)
    assert set(table.status) == {"terminated:impact"}
    assert table.counts() == (12, 0, 0)
    for v0, h0, t, x, mu in zip(
        table["v0"], table["h0"], table["impact.t"], table["impact.x"], table["max_abs.mu_1"]
    ):
        assert t == pytest.approx(impact_time(v0, h0), rel=1e-9)
        assert x == pytest.approx(impact_range(v0, h0), rel=1e-9)
        # |μ| = (m g / 2 v0) tanh(g T / v0) at the impact, where it is largest.
        assert mu == pytest.approx(10.0 / (2 * v0) * math.tanh(10.0 * t / v0), rel=1e-9)
    # The last variable varies fastest.
    assert list(table["h0"][:3]) == [1.0, 5.0, 20.0]
    assert list(table.index) == list(range(12))


def test_random_samples_are_reproducible_and_in_range(scene):
    # The scene ends at t = 10: every point here lands before (T < 6.3 s).
    vary = {"v0": "5:20", "h0": {"from": 1.0, "to": 30.0, "scale": "log"}}
    a = scene.sweep(vary, samples=25, seed=11, design="latin", collect=["impact.t"])
    b = scene.sweep(vary, samples=25, seed=11, design="latin", collect=["impact.t"])
    np.testing.assert_array_equal(a.values, b.values)
    assert np.all((a["v0"] >= 5.0) & (a["v0"] < 20.0))
    assert np.all((a["h0"] >= 1.0) & (a["h0"] < 30.0))
    # A Latin hypercube: one sample in each of the 25 strata of v0.
    assert sorted(((a["v0"] - 5.0) / 15.0 * 25).astype(int)) == list(range(25))
    for v0, h0, t in zip(a["v0"], a["h0"], a["impact.t"]):
        assert t == pytest.approx(impact_time(v0, h0), rel=1e-9)


def test_failed_points_are_rows_with_their_reason(scene):
    table = scene.sweep({"v0": [0.0, 10.0]}, collect=["impact.t"])
    assert table.status == ["refused", "terminated:impact"]
    assert table.reason[0] and not table.reason[1]
    assert math.isnan(table["impact.t"][0])
    assert table.counts() == (1, 0, 1)


def test_shards_written_and_merged_equal_the_whole_sweep(scene, tmp_path):
    vary = {"v0": [4.0, 8.0, 12.0, 16.0, 20.0], "h0": [2.0, 20.0]}
    whole = scene.sweep(vary, collect=["impact.t", "impact.y_dot"])
    files = []
    for k in (1, 2, 3):
        part = scene.sweep(vary, collect=["impact.t", "impact.y_dot"], shard=f"{k}/3")
        assert len(part) in (3, 4)
        files += part.write(tmp_path / "parts")
    merged = chetaev.merge_sweeps(files)
    assert merged.to_csv() == whole.to_csv()
    written = whole.write(tmp_path / "whole")
    # Two variables on a grid: a heat map per quantity, and lines (h0 has two values).
    assert {pathlib.Path(f).name for f in written} == {
        "sweep.csv", "sweep.json", "sweep.svg", "sweep-impact.t.svg", "sweep-impact.y_dot.svg"}
    assert (tmp_path / "whole" / "sweep.csv").read_text() == whole.to_csv()
    with pytest.raises(chetaev.SceneError, match=r"shard\(s\) 2 of 3 missing"):
        chetaev.merge_sweeps([files[0], files[2]])


@pytest.mark.parametrize(
    "kwargs, says",
    [
        ({"vary": {"vo": [1.0]}}, "did you mean v0"),
        ({"vary": {"v0": "0:10:3:log"}}, "cannot reach or cross zero"),
        ({"vary": {"v0": []}}, "the list is empty"),
        ({"vary": {"v0": {"from": 1.0}}}, "give a list of numbers"),
        ({"vary": {"v0": {"from": 1.0, "to": 2.0, "steps": 3}}}, "unknown key 'steps'"),
        ({"vary": {"v0": "1:2"}}, "give `samples`"),
        ({"vary": {"v0": [1.0]}, "collect": ["impact.z"]}, "not a quantity of this scene"),
        ({"vary": {"v0": "1:2:1000", "h0": "1:2:1000", "g": "1:2:1000"}}, "pass yes=True"),
        ({}, "nothing varies"),
    ],
)
def test_bad_specifications_are_refused_before_anything_runs(scene, kwargs, says):
    with pytest.raises(chetaev.ChetaevError, match=says):
        scene.sweep(**kwargs)


def test_a_bad_shard_is_refused(scene):
    with pytest.raises(chetaev.ChetaevError, match="not k/n"):
        scene.sweep({"v0": [1.0]}, shard="0/3")
