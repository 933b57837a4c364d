"""Settings for the whole test run (the notebooks included)."""

import os

# The notebooks read HTETRO_OPT_SMALL: with it they run at small settings (seconds, not minutes);
# their kernels inherit this process's environment.
os.environ.setdefault("HTETRO_OPT_SMALL", "1")

# Hypothesis draws its examples from a fixed seed (derandomize) and keeps no example database, so
# every run of the suite tries the same cases: a failure or a slow case shows up on every run, not
# one run in ten. HYPOTHESIS_PROFILE=explore draws fresh examples for a search of one's own.
from hypothesis import settings  # noqa: E402

settings.register_profile("ci", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
