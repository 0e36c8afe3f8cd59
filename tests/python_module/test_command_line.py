"""`python -m handcentric`: its options are spelled as `handcentric audit` spells them (--group,
--view, --json to stdout); the old spellings (--groups, --views, --json FILE) still work for one
release and say so on stderr."""
import json

from handcentric import __main__ as cli

TARGET = "policies:hand_centric_actions"
SMALL = ["--cases", "10", "--quiet"]


def test_group_view_and_json_as_the_command_spells_them(capsys):
    assert cli.main(["audit", TARGET, "--group", "se3", "translation", "--view", "eye_in_hand",
                     "--json"] + SMALL) == 0
    captured = capsys.readouterr()
    result = json.loads(captured.out)  # the JSON alone on stdout, no summary lines
    assert {c["group"] for c in result["checks"]} == {"se3", "translation"}
    assert {c["view"] for c in result["checks"]} == {"eye_in_hand"}
    assert captured.err == ""
    assert cli.main(["audit", TARGET, "--group", "all", "--view", "eye_in_hand"] + SMALL) == 0
    out = capsys.readouterr().out
    assert all(group in out for group in ("translation", "rotation", "se2", "se3", "c8"))


def test_the_old_spellings_work_and_say_they_are_deprecated(capsys, tmp_path):
    report = tmp_path / "audit.json"
    assert cli.main(["audit", TARGET, "--groups", "se3", "--views", "eye_in_hand", "--json",
                     str(report)] + SMALL) == 0
    captured = capsys.readouterr()
    assert "se3" in captured.out  # the summary lines, as before
    assert json.loads(report.read_text())["checks"]
    for old, new in (("--groups", "--group"), ("--views", "--view"), ("--json FILE", "--json")):
        assert "%s is deprecated: use %s" % (old, new) in captured.err


def test_an_unknown_group_is_a_usage_error_in_either_spelling(capsys):
    for option in ("--group", "--groups"):
        try:
            cli.main(["audit", TARGET, option, "se4"] + SMALL)
        except SystemExit as stop:
            assert stop.code == 2
        else:
            raise AssertionError("no usage error")
        assert "invalid choice: 'se4'" in capsys.readouterr().err


def test_detect_sets_the_cases_as_the_command_does(capsys):
    # --detect 0.05: 90 cases per pointwise cell (mutant: "detect" left out of _keywords ->
    # 1000 cases).
    assert cli.main(["audit", TARGET, "--group", "se3", "--view", "eye_in_hand", "--detect",
                     "0.05", "--json", "--quiet"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["detect"] == {"frequency": 0.05, "cases": 90}
    try:
        cli.main(["audit", TARGET, "--detect", "1.5", "--quiet"])
    except SystemExit as stop:
        assert stop.code == 2
    assert "1.5 is not a frequency in (0, 1)" in capsys.readouterr().err
