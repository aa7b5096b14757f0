"""The run folder's writers (riskassess/products/results.py)."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest

from riskassess.products import results


@pytest.mark.parametrize("seed", range(3))
def test_an_npz_reads_back_the_arrays_numpy_s_own_writer_stores(tmp_path, seed):
    # atomic_write_npz writes numpy's .npy members at its own zlib level (NPZ_COMPRESS_LEVEL); what np.load returns
    # must be what numpy's savez_compressed stores, to the bit: values, dtypes, shapes, names
    rng = np.random.default_rng(seed)
    arrays = {"time": np.cumsum(rng.uniform(0.0, 1e-3, 1000)), "positions_lvlh": rng.normal(0.0, 10.0, (50, 229, 3)),
              "velocities_lvlh": rng.normal(0.0, 1.0, (50, 229, 3)).astype(np.float32),
              "body_names": np.array(["main_body", "solar_array"]), "count": np.int64(7), "rate_deg_s": 2.5,
              "flags": rng.integers(0, 2, 17).astype(bool)}
    results.atomic_write_npz(tmp_path / "ours.npz", arrays)
    np.savez_compressed(tmp_path / "numpy.npz", **arrays)
    with np.load(tmp_path / "ours.npz") as ours, np.load(tmp_path / "numpy.npz") as theirs:
        assert sorted(ours.files) == sorted(theirs.files) == sorted(arrays)
        for key in arrays:
            assert ours[key].dtype == theirs[key].dtype and ours[key].shape == theirs[key].shape
            np.testing.assert_array_equal(ours[key], theirs[key])
    with zipfile.ZipFile(tmp_path / "ours.npz") as archive:
        assert {info.compress_type for info in archive.infolist()} == {zipfile.ZIP_DEFLATED}
