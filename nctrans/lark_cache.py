"""Where lark keeps a grammar's analysed LALR tables between processes.

Building the tables of a grammar takes most of a short run's start-up (~0.2 s for the Sinumerik
grammar); lark can pickle them once and load them after. The file lives in the user's nctrans cache
directory (tables.cache_dir) rather than lark's default shared temporary directory, which another
user could write to. lark checks a hash of the grammar and its options before using the file, and
rebuilds (and tries to rewrite it) when the file is stale, corrupt or unreadable.
"""
from __future__ import annotations

import sys
from typing import Union

from nctrans.tables import cache_dir


def cache_option(name: str) -> Union[str, bool]:
    """Lark's `cache=` argument for the grammar called `name`: a file in the cache directory, or
    False (no caching) when that directory cannot be created."""
    import lark
    d = cache_dir()
    try:
        d.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return str(d / f"{name}-lark{lark.__version__}-py{sys.version_info[0]}{sys.version_info[1]}.lark")
