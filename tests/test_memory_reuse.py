"""A long-lived process (lint over a corpus, the API, the language server) reads program after
program: none of them may stay behind. Freezing each parsed program out of the garbage collector
kept the IR of every program ever read (RSS grew ~31 MiB per pass over the shared corpus)."""
import gc

from conftest import CORPUS

from nctrans import api, cli, pipeline


def _programs(n: int = 12):
    files = sorted(p for p in (CORPUS / "iso-mill").iterdir() if p.is_file())
    return files[:n]


def test_library_reads_freeze_nothing():
    before = gc.get_freeze_count()
    for path in _programs():
        api.lint(path)
        for _ in api.toolpath(path):
            pass
    assert gc.get_freeze_count() == before


def test_command_freezes_at_most_its_budget(monkeypatch, capsys):
    # the `nctrans` command may keep two whole programs (equiv); a third is freed as read
    monkeypatch.setattr(pipeline, "FREEZE_BUDGET", 2)
    frozen = []
    monkeypatch.setattr(gc, "freeze", lambda: frozen.append(1))
    for path in _programs(5):
        pipeline.load(path, None)
    assert len(frozen) == 2
    assert pipeline.FREEZE_BUDGET == 0
    cli.main(["lint", *map(str, _programs(3))])
    capsys.readouterr()
    assert len(frozen) == 2
