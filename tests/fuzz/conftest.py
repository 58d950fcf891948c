"""Hypothesis profiles for the parser fuzzers.

`make test` runs these fuzzers briefly (the default profile); `make fuzz` runs them long with
`--hypothesis-profile=fuzz` (set NCTRANS_FUZZ_EXAMPLES to change the count).
"""
import os

from hypothesis import HealthCheck, settings

settings.register_profile(
    "fuzz",
    max_examples=int(os.environ.get("NCTRANS_FUZZ_EXAMPLES", "20000")),
    deadline=None,
    suppress_health_check=list(HealthCheck),
    print_blob=True,
)
settings.register_profile("default", max_examples=60, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
if not os.environ.get("NCTRANS_FUZZ_PROFILE_SET"):
    settings.load_profile("default")
