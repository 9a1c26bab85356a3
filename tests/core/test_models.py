"""Model files: .npz + JSON round trip, and clear refusals for corrupt or foreign models."""

import json

import numpy as np
import pytest

from tsrkit.plugin.models import Model, ModelError, load_model, save_model


def saved(tmp_path):
    model = Model(
        {"hist": np.arange(12, dtype=np.float32).reshape(3, 4), "bins": np.array([8, 8])},
        info={"states": ["red", "green"]},
    )
    path = save_model(
        tmp_path / "m",
        model,
        plugin="ab-hist",
        plugin_version="1.0",
        params={"bins": (8, 8)},
        training={"checksum": "abc", "samples": 3},
    )
    return model, path


def test_round_trip(tmp_path):
    model, path = saved(tmp_path)
    assert path.name == "m.npz" and (tmp_path / "m.json").is_file()
    loaded = load_model(tmp_path / "m.npz", plugin="ab-hist")
    for key, array in model.arrays.items():
        np.testing.assert_array_equal(loaded.arrays[key], array)
    assert loaded.info == {"states": ["red", "green"]}
    assert loaded.meta["params"] == {"bins": [8, 8]}
    assert loaded.meta["training"]["checksum"] == "abc"


def test_refuses_another_plugins_model(tmp_path):
    saved(tmp_path)
    with pytest.raises(ModelError, match="trained for 'ab-hist', not 'hsi-backprojection'"):
        load_model(tmp_path / "m", plugin="hsi-backprojection")


def test_refuses_corrupt_archive_and_tampered_arrays(tmp_path):
    saved(tmp_path)
    data = (tmp_path / "m.npz").read_bytes()
    (tmp_path / "m.npz").write_bytes(data[: len(data) // 2])
    with pytest.raises(ModelError, match="corrupt archive"):
        load_model(tmp_path / "m", plugin="ab-hist")
    saved(tmp_path)
    meta = json.loads((tmp_path / "m.json").read_text())
    meta["arrays"]["hist"]["sha256"] = "0" * 64
    (tmp_path / "m.json").write_text(json.dumps(meta))
    with pytest.raises(ModelError, match="does not match its checksum"):
        load_model(tmp_path / "m", plugin="ab-hist")


def test_missing_files_and_object_arrays(tmp_path):
    with pytest.raises(ModelError, match="no such file"):
        load_model(tmp_path / "nothing", plugin="x")
    with pytest.raises(ModelError, match="not numeric"):
        save_model(
            tmp_path / "o",
            Model({"o": np.array([object()])}),
            plugin="x",
            plugin_version="1",
            params={},
            training={},
        )
