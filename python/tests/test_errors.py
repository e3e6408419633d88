# Every vdyn::Error arrives as vdyn.Error with the CLI's one-line message, and
# the message names the key path.
import pytest

import vdyn

SCENE = "scenes/ch7_open_loop.json"


def cli_error(cli, *args):
    p = cli(*args, check=False)
    assert p.returncode == 1, p.stderr
    line = p.stderr.strip().splitlines()[-1]
    prefix = f"vdyn {args[0]}: error: "
    assert line.startswith(prefix), line
    return line[len(prefix):]


def test_error_is_an_exception_class():
    assert issubclass(vdyn.Error, Exception)


def test_misspelt_key_on_run(cli):
    key = "plugins.front_steer.command.final_radd"
    expected = cli_error(cli, "run", SCENE, "--no-plots", "--out", "/nonexistent/never", "--set", f"{key}=0.05")
    s = vdyn.Scene.from_file(SCENE).set(key, 0.05)
    with pytest.raises(vdyn.Error) as e:
        s.run()
    assert str(e.value) == expected
    assert "final_radd" in str(e.value) and "\n" not in str(e.value)


def test_bad_value_names_key_path(cli):
    expected = cli_error(cli, "run", SCENE, "--no-plots", "--set", "analysis.t_end_s=-1")
    with pytest.raises(vdyn.Error) as e:
        vdyn.Scene.from_file(SCENE).set("analysis.t_end_s", -1).run()
    assert str(e.value) == expected
    assert "t_end_s" in str(e.value)


def test_bad_key_path_at_set(cli):
    # An array element that does not exist: KeyPath's error, when set.
    key = "plugins.no_such_plugin.speed_m_s"
    expected = cli_error(cli, "run", SCENE, "--no-plots", "--set", f"{key}=3")
    with pytest.raises(vdyn.Error) as e:
        vdyn.Scene.from_file(SCENE).set(key, 3)
    assert str(e.value) == expected
    assert "no_such_plugin" in str(e.value)


def test_missing_file(cli):
    expected = cli_error(cli, "run", "scenes/no_such_scene.json")
    with pytest.raises(vdyn.Error) as e:
        vdyn.Scene.from_file("scenes/no_such_scene.json")
    assert str(e.value) == expected


def test_check_reports_every_error(cli):
    sets = ["plugins.front_steer.command.final_radd=0.05", "analysis.t_end_ss=3"]
    p = cli("check", SCENE, "--set", sets[0], "--set", sets[1], check=False)
    assert p.returncode == 1
    expected = [l[len("vdyn check: error: "):] for l in p.stderr.strip().splitlines()]
    assert len(expected) == 2
    s = vdyn.Scene.from_file(SCENE).set("plugins.front_steer.command.final_radd", 0.05).set("analysis.t_end_ss", 3)
    with pytest.raises(vdyn.Error) as e:
        s.check()
    assert e.value.errors == expected
    assert "final_radd" in e.value.errors[0] and "t_end_ss" in e.value.errors[1]
    assert vdyn.Scene.from_file(SCENE).check() is None


def test_unconvertible_value():
    with pytest.raises(vdyn.Error) as e:
        vdyn.Scene.from_file(SCENE).set("analysis.t_end_s", object())
    assert "analysis.t_end_s" in str(e.value)
