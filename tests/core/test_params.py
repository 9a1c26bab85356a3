"""Parameter schemas: coercion from strings and objects, ranges, choices, and clear errors."""

import pytest

from tsrkit.plugin.params import Param, ParamError, load_config, parse_assignments, validate

SCHEMA = (
    Param("h_peak", "float", 0.9, min=0, max=1),
    Param("n_top", "int", 10, min=1),
    Param("radii", "ints", tuple(range(1, 11)), min=1, max=50),
    Param("weights", "floats", (1.0, 1.0, 1.0), length=3, min=0),
    Param("mode", "str", "max", choices=("max", "saturation")),
    Param("roi", "bool", False),
    Param("model", "path", None),
)


def test_defaults_fill_every_key():
    values = validate(SCHEMA, {}, "detector 'x'")
    assert values == {
        "h_peak": 0.9,
        "n_top": 10,
        "radii": tuple(range(1, 11)),
        "weights": (1.0, 1.0, 1.0),
        "mode": "max",
        "roi": False,
        "model": None,
    }


@pytest.mark.parametrize(
    "given, key, expected",
    [
        ({"h_peak": "0.5"}, "h_peak", 0.5),
        ({"n_top": "3"}, "n_top", 3),
        ({"radii": "2..4"}, "radii", (2, 3, 4)),
        ({"radii": "1,3,5"}, "radii", (1, 3, 5)),
        ({"weights": "1,1,2"}, "weights", (1.0, 1.0, 2.0)),
        ({"weights": (1, 1, 2)}, "weights", (1.0, 1.0, 2.0)),
        ({"roi": "yes"}, "roi", True),
        ({"mode": "saturation"}, "mode", "saturation"),
    ],
)
def test_strings_and_objects_are_coerced(given, key, expected):
    assert validate(SCHEMA, given, "d")[key] == expected


@pytest.mark.parametrize(
    "given, fragment",
    [
        ({"h_peak": "1.5"}, "'h_peak' must be a number in [0, 1]"),
        ({"h_peak": "abc"}, "'h_peak' must be a number"),
        ({"n_top": "2.5"}, "'n_top' must be an integer"),
        ({"n_top": 0}, "out of range"),
        ({"weights": "1,2"}, "of length 3"),
        ({"mode": "median"}, "one of max, saturation"),
        ({"roi": "maybe"}, "true or false"),
        (
            {"hpeak": 1},
            "unknown parameter 'hpeak' (allowed: h_peak, mode, model, n_top, radii, roi, weights)",
        ),
    ],
)
def test_errors_name_plugin_key_and_allowed_values(given, fragment):
    with pytest.raises(ParamError) as info:
        validate(SCHEMA, given, "detector 'x'")
    message = str(info.value)
    assert message.startswith("detector 'x'")
    assert fragment in message
    assert "\n" not in message


def test_parse_assignments():
    assert parse_assignments(["a=1", " b = x=y "]) == {"a": "1", "b": "x=y"}
    with pytest.raises(ParamError, match="key=value"):
        parse_assignments(["novalue"])


def test_load_config_normalises_plugin_entries(tmp_path):
    path = tmp_path / "run.yaml"
    path.write_text("detector: conspicuity\nclassifier:\n  name: ab-hist\n  params: {bins: 8}\n")
    config = load_config(str(path))
    assert config["detector"] == {"name": "conspicuity", "params": {}}
    assert config["classifier"] == {"name": "ab-hist", "params": {"bins": 8}}
    path.write_text("classifier: {params: {}}\n")
    with pytest.raises(ParamError, match="'classifier' must be a name"):
        load_config(str(path))


def test_plugin_typed_values_are_checked_and_written_one_way():
    schema = [
        Param("members", "detectors", "a"),
        Param("before", "verifier", "housing"),
    ]
    values = validate(schema, {"members": " a  k=1 ;b; ", "before": ""}, "p")
    assert values == {"members": "a k=1; b", "before": None}
    for bad in ({"members": ""}, {"members": "a k"}, {"before": "a; b"}, {"before": 3}):
        with pytest.raises(ParamError, match="must be"):
            validate(schema, bad, "p")
    with pytest.raises(ValueError, match="only plugin types take options"):
        Param("k", "int", 1, options=(Param("scale", "float", 1.0),))


def test_a_key_prefixed_with_a_selected_plugins_name_goes_to_that_plugin():
    from tsrkit.plugin.selection import route_params

    routed = route_params(
        {"detector": "gray-tophat", "classifier": "ab-hist"},
        {"gray-tophat.h_peak": 0.8, "ab-hist.model": "m.npz"},
    )
    assert routed == {"detector": {"h_peak": 0.8}, "classifier": {"model": "m.npz"}}
    with pytest.raises(ParamError, match="selected as detector and classifier"):
        route_params({"detector": "sun-pca", "classifier": "sun-pca"}, {"sun-pca.model": "x"})
    with pytest.raises(ParamError, match=r"unknown parameter 'lab-frst\.top'"):
        route_params({"detector": "gray-tophat"}, {"lab-frst.top": 3})
