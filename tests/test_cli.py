"""The command line a newcomer meets first: the shipped scenarios with their files, a scenario to
copy, a rerun into the default folder, and the live view's recording without a terminal."""

import importlib.metadata
import io
import subprocess
import sys
import time
import urllib.request

import numpy as np
import pytest

import browser
from drake_traj import catalogue, cli
from drake_traj.cli import commands
from drake_traj.robots import ROBOT_NAMES, get_robot
from drake_traj.scenario import load_scenario, shipped_scenarios


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["no-such-command"]])
def test_version_and_help_do_not_import_drake(argv):
    # the console script imports drake_traj.cli: it, and the package, must answer these alone
    code = ("import sys\nfrom drake_traj import cli\ncode = cli.main(sys.argv[1:])\n"
            "heavy = sorted(m for m in sys.modules if m.split('.')[0] in ('pydrake', 'numpy', 'matplotlib', 'distributed'))\n"
            "print('imported:', heavy, 'exit', code)")
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=60)
    assert done.stdout.splitlines()[-1] == f"imported: [] exit {2 if argv[0] == 'no-such-command' else 0}", done



def test_a_reader_that_stops_early_is_no_error():
    # drake-traj list | head -1: the pipe is closed while the list is printed (here before any line)
    process = subprocess.Popen([sys.executable, "-m", "drake_traj.cli", "list"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    process.stdout.close()
    assert process.wait(timeout=120) == cli.EXIT_OK
    assert process.stderr.read() == ""
    process.stderr.close()


def test_the_version_is_the_installed_packages(capsys):
    assert cli.main(["--version"]) == cli.EXIT_OK
    assert capsys.readouterr().out == f"drake-traj {importlib.metadata.version('drake_traj')}\n"


def test_a_commands_help_lists_its_options(capsys):
    assert cli.main(["export", "--help"]) == cli.EXIT_OK
    assert "--format {csv,ros2,urscript}" in capsys.readouterr().out


@pytest.mark.parametrize("verbose", [False, True])
def test_list_gives_each_shipped_files_name_above_its_scenarios(verbose, capsys):
    # by default the file's name (no absolute path); -v its path, below which copy of the files runs
    assert cli.main(["list", "-v"] if verbose else ["list"]) == cli.EXIT_OK
    lines = capsys.readouterr().out.splitlines()[1:]  # below the heading
    for entry in shipped_scenarios():
        header = lines.index(str(entry.path) if verbose else entry.path.name)
        below = lines[header + 1:]
        below = below[:next((k for k, line in enumerate(below) if not line.startswith("  ")), len(below))]
        assert any(line.split()[0] == entry.name for line in below), (entry.name, lines)
    assert any(line.startswith("/") for line in lines) == verbose


def test_only_list_v_and_show_where_say_which_copy_of_the_shipped_files_runs(capsys, monkeypatch, tmp_path):
    """A source tree's diagrams/ (a checkout, an editable install: an edit changes what runs) or
    the installed package's (CI installs it so): said by list -v's first line and show --where,
    never by list and show themselves, which name no absolute path."""
    directory = shipped_scenarios()[0].path.parent
    here = catalogue.shipped_copy()
    in_tree = (directory.parent / "pyproject.toml").is_file()
    assert here.startswith("this source tree's diagrams/" if in_tree else "the installed package") and str(directory) in here
    assert cli.main(["list", "-v"]) == cli.EXIT_OK
    assert capsys.readouterr().out.splitlines()[0] == f"shipped scenarios, from {here}"
    assert cli.main(["show", "quintic_ptp", "--where"]) == cli.EXIT_OK
    where = capsys.readouterr()
    assert where.out == f"{directory / 'quintic_ptp.yaml'}\n" and where.err == f"drake-traj: from {here}\n"
    for argv in (["list"], ["show", "quintic_ptp"], ["robots"]):
        assert cli.main(argv) == cli.EXIT_OK
        captured = capsys.readouterr()
        assert str(directory) not in captured.out + captured.err, argv
    for tree in (True, False):  # both wordings, whichever way this copy is installed
        folder = tmp_path / str(tree) / "diagrams"
        folder.mkdir(parents=True)
        if tree:
            (folder.parent / "pyproject.toml").write_text("[project]\n")
        monkeypatch.setattr(catalogue, "shipped_directory", lambda folder=folder: folder)
        said = catalogue.shipped_copy()
        assert said.startswith("this source tree's diagrams/" if tree else "the installed package") and str(folder) in said


def test_an_installed_copy_says_a_checkouts_diagrams_are_not_read(tmp_path, monkeypatch, capsys):
    installed = tmp_path / "site-packages" / "drake_traj" / "diagrams"  # no pyproject.toml beside it
    installed.mkdir(parents=True)
    (installed / "quintic_ptp.yaml").write_text((shipped_scenarios()[0].path.parent / "quintic_ptp.yaml").read_text())
    monkeypatch.setattr(catalogue, "shipped_directory", lambda: installed)
    assert cli.main(["list", "-v"]) == cli.EXIT_OK
    assert capsys.readouterr().out.splitlines()[:2] == [
        f"shipped scenarios, from the installed package ({installed}; a checkout's diagrams/ is not read: copy a "
        "scenario with drake-traj show NAME > my_task.yaml, edit the copy and run it by its path)",
        str(installed / "quintic_ptp.yaml")]
    assert cli.main(["list"]) == cli.EXIT_OK
    assert capsys.readouterr().out.splitlines()[1:3] == ["quintic_ptp.yaml", "  quintic_ptp  ur10e  Benotsmane et al.'s "
                                                         "synchronised quintic moves through three joint goals and back"]


@pytest.mark.parametrize("argv, variant", [(["show", "quintic_ptp"], None), (["show", "pajak_sim3"], "sim3"),
                                           (["show", "pajak", "--variant", "sim2"], "sim2")])
def test_show_prints_the_shipped_file_to_copy_and_run(argv, variant, tmp_path, capsys):
    assert cli.main(argv) == cli.EXIT_OK
    captured = capsys.readouterr()
    shipped = next(entry for entry in shipped_scenarios()
                   if entry.name == argv[1] or (entry.path.stem, entry.variant) == (argv[1], variant))
    assert captured.out == shipped.path.read_text()
    assert f"that is the shipped file {shipped.path.name} (--where: its path); run a copy with" in captured.err
    assert ("--variant " + variant in captured.err) if variant else "--variant" not in captured.err
    copy = tmp_path / "my_copy.yaml"
    copy.write_text(captured.out)
    assert load_scenario(copy, variant).planner == load_scenario(shipped.path, variant).planner


def test_show_of_a_file_of_variants_names_them(capsys):
    assert cli.main(["show", "pajak"]) == cli.EXIT_OK
    assert "run a copy with: drake-traj run my_copy.yaml --variant sim1|sim2|sim3" in capsys.readouterr().err


def test_a_rerun_into_the_default_folder_names_the_overwrite_flag(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    earlier = tmp_path / "out" / "quintic_ptp"
    earlier.mkdir(parents=True)
    (earlier / "result.npz").write_bytes(b"an earlier run")
    assert cli.main(["run", "quintic_ptp"]) == cli.EXIT_BAD_INPUT
    err = capsys.readouterr().err
    assert "output folder out/quintic_ptp holds an earlier run" in err and "pass --overwrite" in err, err
    assert (earlier / "result.npz").read_bytes() == b"an earlier run"


class Stdin(io.StringIO):
    def __init__(self, terminal: bool):
        super().__init__()
        self._terminal = terminal

    def isatty(self) -> bool:
        return self._terminal


@pytest.mark.parametrize("terminal, serve_after, slept", [(False, None, commands.DEFAULT_SERVE_AFTER), (False, 2.5, 2.5),
                                                          (True, 2.5, 2.5), (False, 0.0, None)])
def test_the_recording_is_served_for_serve_after_seconds(terminal, serve_after, slept, monkeypatch, capsys):
    # without a terminal (a script, CI, an IDE) there is no Ctrl-C prompt: the recording stays
    # served for --serve-after seconds (default 60); on a terminal too when it is given
    sleeps = []
    monkeypatch.setattr(sys, "stdin", Stdin(terminal))
    monkeypatch.setattr(commands, "sleep", sleeps.append)
    commands.serve_recording("http://localhost:7000", serve_after)
    assert sleeps == ([] if slept is None else [slept])
    err = capsys.readouterr().err
    assert (f"serving the recording at http://localhost:7000 for {slept:g} s" in err) if slept else not err


def test_a_live_run_without_a_terminal_serves_its_recording_then_exits(tmp_path):
    port = browser.free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "drake_traj.cli", "run", "quintic_ptp", "--out", str(tmp_path / "live"), "--meshcat",
         "--no-wait", "--rate", "100", "--port", str(port), "--serve-after", "1.5"],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        serving = browser.read_until(process.stderr, "serving the recording", timeout=180)
        start = time.monotonic()
        assert f"at http://localhost:{port} for 1.5 s" in serving
        with urllib.request.urlopen(f"http://localhost:{port}", timeout=5) as page:  # still served
            assert page.status == 200
        assert process.wait(timeout=60) == cli.EXIT_OK
        assert time.monotonic() - start > 0.5
    finally:
        process.kill()


def test_list_shows_each_shipped_scenarios_robot(capsys):
    assert cli.main(["list"]) == cli.EXIT_OK
    rows = {line.split()[0]: line.split()[1] for line in capsys.readouterr().out.splitlines() if line.startswith("  ")}
    for entry in shipped_scenarios():
        robot = load_scenario(entry.path, entry.variant).robot  # a name, or an arm of one's own
        assert rows[entry.name] == (robot if isinstance(robot, str) else robot.name)
    assert rows["li_closed_path_4dof"] == "li_4dof" and rows["pajak_sim3"] == "ur10e"
    assert rows["puma560_pajak"] == "puma560"


def test_robots_tabulates_every_known_robot_with_its_ratings(capsys):
    assert cli.main(["robots"]) == cli.EXIT_OK
    header, *lines = capsys.readouterr().out.splitlines()
    assert header.split()[:2] == ["robot", "joints"] and "data source" in header
    rows = {line.split()[0]: line for line in lines}
    assert set(ROBOT_NAMES) <= set(rows)
    for name in ROBOT_NAMES:
        robot = get_robot(name)
        n = robot.num_joints
        fields = rows[name].split()
        assert fields[1] == str(n)
        assert fields[2] == ("-" if robot.reach is None else f"{robot.reach:g}")
        assert fields[3] == ("-" if robot.rated_payload is None else f"{robot.rated_payload:g}")
        np.testing.assert_allclose(np.array(fields[4:4 + n], dtype=float), robot.velocity_limits, rtol=5e-4)
        np.testing.assert_allclose(np.array(fields[4 + n:4 + 2 * n], dtype=float), robot.effort_limits, rtol=5e-4)
        assert rows[name].endswith(robot.data_source)
        # an installed package has no docs/ folder: the source is said in words (the manual's page by its title)
        assert robot.data_source and "docs/" not in robot.data_source and ".md" not in robot.data_source, robot.data_source
    ur10e = rows["ur10e"].split()
    assert ur10e[1:4] == ["6", "1.3", "12.5"] and ur10e[4:6] == ["2.094", "2.094"] and ur10e[10:16] == ["330", "330", "150", "56", "56", "56"]
