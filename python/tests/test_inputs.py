"""Every value from Python is checked where it enters, by the library's rules, with messages that name the
keyword (not a command-line flag) and never a bare OverflowError: regression tests named after the
symptoms a hostile tester found."""

import pytest

import vrw
from conftest import cli_error


def test_sweep_viscosity_minus_one_is_refused_not_a_gait_found_threshold():
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.sweep(vrw.Params(), "viscosity", [1, 2, -1])
    message = str(raised.value)
    assert "sweep viscosity" in message and "-1" in message
    assert "must be non-negative" in message


def test_sweep_rtol_to_one_is_refused_not_a_gait_lost_threshold():
    with pytest.raises(vrw.ConfigError, match="must be between 1e-14 and 0.001"):
        vrw.sweep(vrw.Params(), "rtol", [1e-10, 1.0])


@pytest.mark.parametrize("fd_step", [1e-16, 1e-18, 0.0, float("nan")])
def test_find_gait_fd_step_1e_minus_16_is_refused_not_unstable(fd_step):
    with pytest.raises(vrw.ConfigError, match="`fd_step`"):
        vrw.find_gait(vrw.Params(), fd_step=fd_step)


def test_transient_0_tolerance_1_is_refused_with_the_command_lines_rule(cli, tmp_path):
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.find_gait(vrw.Params(), transient_steps=0, tolerance=1.0)
    done = cli("gait", "--transient", 0, "--tolerance", 1, "--out", tmp_path, check=False)
    # The same rule; the command line names its flag, Python the keyword.
    assert cli_error(done) == "gait: " + str(raised.value).replace("`tolerance`", "`--tolerance`")


@pytest.mark.parametrize(
    "options, keyword",
    [
        ({"transient_steps": -1}, "transient_steps"),
        ({"transient_steps": 10**30}, "transient_steps"),
        ({"transient_steps": 100_000_000}, "transient_steps"),
        ({"max_iterations": -5}, "max_iterations"),
    ],
)
def test_out_of_range_counts_name_the_keyword_not_overflow_error(options, keyword):
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.find_gait(vrw.Params(), **options)
    assert f"`{keyword}`" in str(raised.value)
    assert not isinstance(raised.value, OverflowError)


def test_simulate_bad_steps_and_sample_dt_name_the_keyword_not_a_flag():
    for kwargs, keyword in [
        ({"steps": -1}, "steps"),
        ({"steps": 0}, "steps"),
        ({"steps": 10**20}, "steps"),
        ({"sample_dt": 0.0}, "sample_dt"),
        ({"sample_dt": 1e-300}, "sample_dt"),
    ]:
        with pytest.raises(ValueError) as raised:
            vrw.simulate(vrw.Params(), **kwargs)
        message = str(raised.value)
        assert keyword in message and "--" not in message, message
    with pytest.raises(TypeError, match="`sample_dt`"):
        vrw.simulate(vrw.Params(), sample_dt="fast")


def test_linspace_of_a_billion_points_is_refused_not_killed_for_memory():
    with pytest.raises(vrw.ConfigError, match="between 2 and 100000"):
        vrw.linspace(1, 2, 10**9)
    with pytest.raises(vrw.ConfigError, match="`points`"):
        vrw.linspace(1, 2, -3)
    assert vrw.linspace(1, 2, 3) == [1.0, 1.5, 2.0]


def test_stiff_legs_are_refused_and_slow_ones_warn():
    with pytest.raises(vrw.ConfigError, match="too stiff"):
        vrw.Params(viscosity=1e9)
    with pytest.warns(RuntimeWarning, match="stiff legs"):
        vrw.Params(viscosity=1e5)


def test_every_broken_rule_is_listed(cli, tmp_path):
    with pytest.raises(vrw.ConfigError) as raised:
        vrw.Params(stopper_length=0.2, spring_natural_length=0.1, rtol=1)
    message = str(raised.value)
    assert message.startswith("4 problems: 1) ")
    done = cli(
        "simulate", "--steps", 1, "--out", tmp_path,
        "--set", "stopper_length=0.2", "--set", "spring_natural_length=0.1", "--set", "rtol=1",
        check=False,
    )
    assert cli_error(done) == message
