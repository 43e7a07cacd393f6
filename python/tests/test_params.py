"""vrw.Params: every TOML key as a keyword, validated as the command line does, with its messages."""

import pickle

import pytest

import vrw
from conftest import ROOT, cli_error


def test_defaults_and_keywords_match_the_toml_keys():
    defaults = vrw.Params().to_dict()
    p = vrw.Params(viscosity=37, legs=6, impact="traditional", rigid_legs=False)
    d = p.to_dict()
    assert d.keys() == defaults.keys()
    assert d["viscosity"] == 37.0 and isinstance(d["viscosity"], float)
    assert d["legs"] == 6 and d["impact"] == "traditional"
    assert {k for k in d if d[k] != defaults[k]} == {"viscosity", "legs", "impact"}
    assert p["viscosity"] == 37.0
    assert set(vrw.Params.numeric_keys()) <= set(defaults)


def test_the_keys_files_leave_out_at_their_defaults_are_keys_too(tmp_path):
    # rear_exit and rear_stopper are not written at their defaults (files stay as before them), but they are keys.
    defaults = vrw.Params()
    assert defaults["rear_exit"] == "relock" and defaults["rear_stopper"] is True
    third_party = vrw.Params.from_toml(ROOT / "readings" / "third-party-reset.toml")
    assert third_party == vrw.Params(rear_exit="reset", rear_stopper=False)
    assert repr(third_party) == "Params(rear_exit='reset', rear_stopper=False)"
    assert pickle.loads(pickle.dumps(third_party)) == third_party
    assert vrw.Params(**third_party.to_dict()) == third_party
    # min_length (the compression stop; 0, none, by default) is such a key, and a numeric one.
    assert defaults["min_length"] == 0.0 and "min_length" in vrw.Params.numeric_keys()
    assert defaults["touchdown_length"] == 0.0 and "touchdown_length" in vrw.Params.numeric_keys()
    stroke = vrw.Params.from_toml(ROOT / "readings" / "stroke-limited.toml")
    assert stroke["min_length"] == 1.0 and stroke == vrw.Params(**stroke.to_dict())
    assert pickle.loads(pickle.dumps(stroke)) == stroke
    # friction (infinity, no slip, by default) is such a key too; a finite one round-trips.
    assert defaults["friction"] == float("inf") and "friction" in vrw.Params.numeric_keys()
    slippery = vrw.Params(friction=0.6)
    assert slippery["friction"] == 0.6 and vrw.Params(**slippery.to_dict()) == slippery
    assert pickle.loads(pickle.dumps(slippery)) == slippery


def test_from_toml_equals_keywords(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text('viscosity = 37\nimpact = "traditional"\n')
    assert vrw.Params.from_toml(path) == vrw.Params(viscosity=37.0, impact="traditional")


def test_replace_and_round_trips():
    p = vrw.Params(viscosity=37)
    q = p.replace(stiffness=600)
    assert q == vrw.Params(viscosity=37, stiffness=600) and p == vrw.Params(viscosity=37)
    assert vrw.Params(**q.to_dict()) == q
    # Every protocol (0 and 1 used to fail: only __getnewargs_ex__ was defined).
    for protocol in range(pickle.HIGHEST_PROTOCOL + 1):
        assert pickle.loads(pickle.dumps(q, protocol=protocol)) == q, protocol
    assert repr(q) == "Params(stiffness=600.0, viscosity=37.0)"


@pytest.mark.parametrize(
    "keys, override",
    [
        ({"no_such_key": 1}, "no_such_key=1"),
        ({"viscosity": -1}, "viscosity=-1"),
        ({"hub_mass": 0.0}, "hub_mass=0"),
        ({"legs": 2}, "legs=2"),
        ({"spring_natural_length": 0.5}, "spring_natural_length=0.5"),
        ({"impact": "elastic"}, "impact=elastic"),
        ({"inconsistent_contact": "bounce"}, "inconsistent_contact=bounce"),
        ({"integrator": "rk4"}, "integrator=rk4"),
        ({"rear_exit": "drop"}, "rear_exit=drop"),
        ({"rear_stopper": False}, "rear_stopper=false"),
        ({"spring_natural_length": 0.99}, "spring_natural_length=0.99"),
        ({"min_length": 1.0}, "min_length=1"),
        ({"min_length": -0.5}, "min_length=-0.5"),
        ({"touchdown_length": 0.9}, "touchdown_length=0.9"),
        ({"friction": -0.1}, "friction=-0.1"),
        ({"friction": float("nan")}, "friction=nan"),
    ],
)
def test_bad_keys_raise_the_command_lines_message(cli, tmp_path, keys, override):
    with pytest.raises(ValueError) as raised:
        vrw.Params(**keys)
    assert isinstance(raised.value, vrw.ConfigError)
    done = cli("simulate", "--steps", "1", "--out", tmp_path, "--set", override, check=False)
    assert str(raised.value) == cli_error(done)
    with pytest.raises(vrw.ConfigError) as again:
        vrw.Params().replace(**keys)
    assert str(again.value) == str(raised.value)


@pytest.mark.parametrize("toml, keys", [('viscosity = "abc"', {"viscosity": "abc"}), ("legs = 8.0", {"legs": 8.0}), ("rigid_legs = 1", {"rigid_legs": 1})])
def test_wrong_types_raise_the_config_files_message(cli, tmp_path, toml, keys):
    path = tmp_path / "bad.toml"
    path.write_text(toml + "\n")
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.Params(**keys)
    done = cli("simulate", "--steps", "1", "--out", tmp_path, "--config", path, check=False)
    assert str(raised.value) == cli_error(done)
    with pytest.raises(vrw.ConfigError) as from_file:
        vrw.Params.from_toml(path)
    assert str(from_file.value) == str(raised.value)


def test_numpy_scalars_are_their_values():
    np = pytest.importorskip("numpy")
    assert vrw.Params(viscosity=np.float32(37), legs=np.int64(6)) == vrw.Params(viscosity=37, legs=6)


def test_unsupported_types_are_type_errors():
    with pytest.raises(TypeError):
        vrw.Params(viscosity=[1, 2])
