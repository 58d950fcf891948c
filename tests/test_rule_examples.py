"""Every rule in the catalogue (rules/lint-rules.toml) proves itself on its own examples.

Parametrised over the catalogue as it is read at run time, so a rule added later is tested without
touching this file: its `bad` program must report the rule, its `good` program must not. An example
that is prose rather than a program, or that needs a file or a machine it does not declare, fails
here with a message that says so.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from nctrans import catalogue, cli, pipeline

CATALOGUE = catalogue.load()
RULE_IN_OUTPUT = re.compile(r"\[(NC\d{3})\]")


def _example_file(tmp: Path, rule: catalogue.Rule, text: str, encoding: str) -> Path:
    ending = (pipeline.get_dialect(rule.dialect).extensions or (".nc",))[0] if rule.dialect else ".nc"
    for name, content in rule.example_files.items():
        (tmp / name).write_text(content, encoding="utf-8")
    path = tmp / f"example{ending}"
    path.write_bytes(text.encode(encoding))
    return path


def _run_example(rule: catalogue.Rule, text: str, tmp: Path, capsys, encoding="utf-8") -> tuple[set[str], str]:
    """(rule codes reported, the output) for one example run as the catalogue says."""
    path = _example_file(tmp, rule, text, encoding)
    argv = [rule.example_command, str(path), "--from", rule.dialect, *rule.example_args]
    if rule.example_machine is not None:
        machine = tmp / "machine.toml"
        machine.write_text(rule.example_machine, encoding="utf-8")
        argv += ["--machine", str(machine)]
    if rule.example_command == "convert":
        argv += ["-o", str(tmp / "converted.out")]
    if rule.example_command == "backplot":
        argv += ["-o", str(tmp / "plot.svg")]
    capsys.readouterr()
    status = cli.main(argv)
    out = capsys.readouterr()
    text_out = out.out + out.err
    assert status in (0, 1), f"{rule.code}: `nctrans {' '.join(argv)}` failed to run (exit {status}):\n{text_out}"
    return set(RULE_IN_OUTPUT.findall(text_out)), text_out


def _how(rule: catalogue.Rule) -> str:
    return (f"the example is run as `{catalogue._example_context(rule)}`; if it needs other files or a "
            f"machine, declare example_files / example_machine / example_args in rules/lint-rules.toml")


@pytest.mark.parametrize("rule", CATALOGUE.rule, ids=lambda r: r.code)
def test_bad_example_reports_the_rule(rule, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name, value in rule.example_env.items():      # limits lowered for a short example
        monkeypatch.setenv(name, value)
    assert rule.bad.strip() or rule.code == "NC004", f"{rule.code} has no failing example (`bad`)"
    codes, output = _run_example(rule, rule.bad, tmp_path, capsys, rule.example_encoding)
    if rule.reserved:
        assert rule.code not in codes, (f"{rule.code} is declared reserved in rules/lint-rules.toml "
                                        f"({rule.reserved}) but its example now reports it: drop `reserved`")
        return
    assert rule.code in codes, (f"{rule.code}'s failing example does not report {rule.code} ({_how(rule)}).\n"
                                f"example:\n{rule.bad}\noutput:\n{output}")


@pytest.mark.parametrize("rule", CATALOGUE.rule, ids=lambda r: r.code)
def test_good_example_does_not_report_the_rule(rule, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name, value in rule.example_env.items():      # limits lowered for a short example
        monkeypatch.setenv(name, value)
    assert rule.good.strip(), f"{rule.code} has no passing example (`good`)"
    codes, output = _run_example(rule, rule.good, tmp_path, capsys)
    assert rule.code not in codes, (f"{rule.code}'s passing example reports {rule.code} ({_how(rule)}).\n"
                                    f"example:\n{rule.good}\noutput:\n{output}")
    assert not {c for c in codes if c.startswith("NC0")}, \
        f"{rule.code}'s passing example has syntax errors:\n{output}"
