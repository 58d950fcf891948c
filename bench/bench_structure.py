"""Structural-conversion share per direction on the shared corpus (`make bench`).

For each real program of ../shared/corpus: ISO milling programs (iso-mill/) converted to Sinumerik,
Sinumerik programs and subprogram files (sinumerik/*.mpf, *.spf, *.drs; not the .def definition
files) converted to ISO milling. Each conversion is one of:
- structural: converted with the program's structure kept (at most single constructs lowered to
  plain motion, each an NC401 at its line) and the output reads back in the target with no error;
- flattened: converted only as plain motion for the whole program;
  A construct the target cannot express and that cannot be lowered to plain motion (in a
  subprogram file converted to ISO; in any program converted to Sinumerik) is written as an alarm
  at its place (NC412, the same count both ways; listed per file with -v): the file is structural,
  but stops there until ported;
- refused: not converted (NC4xx or other errors name why), or the output does not read back clean.
`structure_share()` is what tests/test_structure_share.py asserts the issue's thresholds on.
Not timed; no assertions here.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CORPUS = ROOT.parent / "shared" / "corpus"
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

DIRECTIONS = (
    ("iso-mill", "iso-m", "sinumerik", None),
    ("sinumerik", "sinumerik", "iso-m", (".mpf", ".spf", ".drs")),
)


@dataclass
class Outcome:
    file: str
    state: str                      # structural | flattened | refused
    why: str = ""
    lowered_constructs: int = 0     # per-construct lowerings to plain motion (NC401 "lowered to plain motion")
    refused_in_place: int = 0       # constructs written as an alarm at their place (NC412)
    first_in_place: int = 0         # the source line of the first of them


@dataclass
class Share:
    source: str
    target: str
    outcomes: list[Outcome] = field(default_factory=list)

    def count(self, state: str) -> int:
        return sum(1 for o in self.outcomes if o.state == state)

    @property
    def share(self) -> float:
        return self.count("structural") / len(self.outcomes) if self.outcomes else 0.0


def corpus_files(corpus: Path, folder: str, endings) -> list[Path]:
    d = corpus / folder
    if not d.is_dir():
        return []
    return sorted(p for p in d.iterdir()
                  if p.is_file() and not p.name.startswith(".")
                  and (endings is None or p.suffix.lower() in endings))


def classify(path: Path, source: str, target: str) -> Outcome:
    import nctrans
    from nctrans.convert import WHOLE_PROGRAM_NOTE, CONSTRUCT_NOTE
    try:
        conv = nctrans.transpile(path, read=source, write=target)
    except Exception as e:           # a crash is a refusal here; tests catch crashes elsewhere
        return Outcome(path.name, "refused", f"internal error: {e!r}"[:200])
    if conv.text is None:
        errs = [d for d in conv.diagnostics if d.severity == "error"]
        why = f"line {errs[0].line}: [{errs[0].rule}] {errs[0].message}" if errs else "refused"
        return Outcome(path.name, "refused", why[:200])
    if any(WHOLE_PROGRAM_NOTE in d.message for d in conv.diagnostics):
        return Outcome(path.name, "flattened", "the whole program was lowered to plain motion")
    from nctrans.dialects.base import get
    back = get(target).parse(conv.text, path.name)
    errs = [d for d in back.diagnostics if d.severity == "error"]
    if errs:
        return Outcome(path.name, "refused", f"output does not read back: line {errs[0].line} "
                       f"[{errs[0].rule}] {errs[0].message}"[:200])
    constructs = sum(1 for d in conv.diagnostics if CONSTRUCT_NOTE in d.message)
    in_place = [d.line for d in conv.diagnostics if d.rule == "NC412"]
    return Outcome(path.name, "structural", lowered_constructs=constructs, refused_in_place=len(in_place),
                   first_in_place=min(in_place, default=0))


def structure_share(corpus: Path = CORPUS) -> list[Share]:
    shares = []
    for folder, source, target, endings in DIRECTIONS:
        share = Share(source, target)
        for path in corpus_files(corpus, folder, endings):
            share.outcomes.append(classify(path, source, target))
        shares.append(share)
    return shares


def main() -> int:
    if not CORPUS.is_dir():
        print(f"structural conversion: corpus not found at {CORPUS}")
        return 0
    print("Structural conversion share on the shared corpus")
    print(f"{'direction':<24}{'files':>7}{'structural':>12}{'flattened':>11}{'refused':>9}"
          f"{'share':>8}{'constructs lowered':>20}{'refused in place':>18}")
    shares = structure_share()
    for s in shares:
        lowered = sum(o.lowered_constructs for o in s.outcomes)
        in_place = sum(o.refused_in_place for o in s.outcomes)
        print(f"{s.source + ' -> ' + s.target:<24}{len(s.outcomes):>7}{s.count('structural'):>12}"
              f"{s.count('flattened'):>11}{s.count('refused'):>9}{100 * s.share:>7.0f}%{lowered:>20}"
              f"{in_place:>18}")
    if "-v" in sys.argv[1:]:
        for s in shares:
            for o in s.outcomes:
                if o.state != "structural":
                    print(f"  {s.source}->{s.target} {o.state:<10} {o.file}: {o.why}")
                elif o.refused_in_place:
                    print(f"  {s.source}->{s.target} structural {o.file}: {o.refused_in_place} "
                          f"constructs refused in place (NC412 alarm lines), the first at line "
                          f"{o.first_in_place}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
