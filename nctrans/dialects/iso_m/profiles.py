"""Control profiles of the ISO milling family (rules/iso-m.toml [options.profiles]): which control
of the family a program was written for changes what some numbered variables are (Haas
#10000-#10999 are plain common variables; on a Fanuc 30i the same numbers are tool offsets).
The profile is named by the user (`convert --profile`) or detected from the header comments."""
from __future__ import annotations

import re
from typing import Optional

# header comments are looked for in this much of the text: detection stays flat in program size
_HEADER_CHARS = 4000
_COMMENT = re.compile(r"\(([^()\n]*)\)")


def detect(text: str, options: dict) -> Optional[str]:
    """The profile whose `detect` pattern a header comment matches, or None."""
    profiles = options.get("profiles") or {}
    comments = _COMMENT.findall(text[:_HEADER_CHARS])
    for name, p in profiles.items():
        for pattern in p.get("detect", ()):
            rx = re.compile(pattern, re.IGNORECASE)
            if any(rx.search(c) for c in comments):
                return name
    return None


def detect_by_block(text: str, options: dict) -> Optional[tuple[str, int, str]]:
    """(profile, line, block text) of the first block only one profile's control reads (its
    `detect_blocks` patterns, outside comments), or None: a regular-expression scan per pattern."""
    for name, p in (options.get("profiles") or {}).items():
        for pattern in p.get("detect_blocks", ()):
            for m in re.finditer(pattern, text, re.IGNORECASE):
                start = text.rfind("\n", 0, m.start()) + 1
                before = text[start:m.start()]
                if "(" in before or ";" in before:
                    continue            # in a comment
                end = text.find("\n", m.end())
                block = text[start:end if end >= 0 else len(text)].strip()
                return name, text.count("\n", 0, start) + 1, block
    return None


def common_ranges(meta: Optional[dict]) -> list[tuple[int, int]]:
    """The number ranges the program's profile makes plain common variables (none without one)."""
    meta = meta or {}
    name = meta.get("profile")
    profile = ((meta.get("options") or {}).get("profiles") or {}).get(name) if name else None
    return [(int(a), int(b)) for a, b in (profile or {}).get("common_variables", ())]


def is_common(number, meta: Optional[dict]) -> bool:
    return isinstance(number, int) and any(a <= number <= b for a, b in common_ranges(meta))
