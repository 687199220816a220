"""The dynamic answers (reactions, section forces, stress envelope) are recorded over a
chunk's rows in blocks (DynamicAnswers' ANSWER_BLOCK_BYTES, issue 23: the recorder's work arrays held ~5
copies of a chunk's full coordinates): any block size gives the same answers, also where the reactions need the accelerations rebuilt row by row across blocks (the
knuckle crane's eliminated joints). The matrix products of a block of one row and of
many rows may round differently (BLAS gemv against gemm): the answers agree to 1e-12 of
each series' magnitude (SPEC's gate for a changed arithmetic order)."""
from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np

from ancfdrv import runner
from ancfdrv.system import answers

ROOT = Path(__file__).resolve().parents[1]


def _answers(path: Path) -> dict[str, np.ndarray]:
    out = {}
    with h5py.File(path, "r") as h5:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset) and name.startswith(
                    ("dynamic/reactions", "dynamic/sections", "dynamic/stress")):
                out[name] = obj[()]
        h5.visititems(visit)
    return out


def test_row_blocks_give_the_same_answers(tmp_path, monkeypatch):
    scene = ROOT / "inputs/knuckle_crane_rope.nml"
    overrides = ["solver.t_end=0.1"]
    runner.run_scene(scene, overrides, tmp_path / "whole.h5", progress=False)
    monkeypatch.setattr(answers, "ANSWER_BLOCK_BYTES", 1)   # one row per block
    calls = []
    call, record = answers.DynamicAnswers.__call__, answers.DynamicAnswers._record

    def counting(self, chunk):
        calls.append([len(chunk.time), 0])
        call(self, chunk)

    def counting_blocks(self, chunk):
        calls[-1][1] += 1
        record(self, chunk)

    monkeypatch.setattr(answers.DynamicAnswers, "__call__", counting)
    monkeypatch.setattr(answers.DynamicAnswers, "_record", counting_blocks)
    runner.run_scene(scene, overrides, tmp_path / "rows.h5", progress=False)
    assert any(rows > 1 and parts == rows for rows, parts in calls)
    whole, rows = _answers(tmp_path / "whole.h5"), _answers(tmp_path / "rows.h5")
    assert any(k.startswith("dynamic/reactions") for k in whole) and set(whole) == set(rows)
    worst = 0.0
    for name, values in whole.items():
        scale = float(np.max(np.abs(values)))
        diff = float(np.max(np.abs(values - rows[name])))
        worst = max(worst, diff / scale if scale > 0 else diff)
    print("largest difference relative to the series' magnitude", worst)
    assert worst <= 1e-12
