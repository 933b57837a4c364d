"""Settings for the whole test run (the notebooks included)."""

import os

# The notebooks read HTETRO_OPT_SMALL: with it they run at small settings (seconds, not minutes);
# their kernels inherit this process's environment.
os.environ.setdefault("HTETRO_OPT_SMALL", "1")

# Hypothesis draws its examples from a fixed seed (derandomize) and keeps no example database, so
# every run of the suite tries the same cases: a failure or a slow case shows up on every run, not
# one run in ten. HYPOTHESIS_PROFILE=explore draws fresh examples for a search of one's own.
# Neither profile reads the clock: no per-example deadline and no "too slow" health check (both
# are wall-clock budgets, which fail on a busy machine, not on a wrong answer); a test's own
# settings that list health checks to suppress must list too_slow again, since they replace these.
from hypothesis import HealthCheck, settings  # noqa: E402

_UNTIMED = {"deadline": None, "suppress_health_check": [HealthCheck.too_slow]}
settings.register_profile("ci", derandomize=True, database=None, **_UNTIMED)
settings.register_profile("explore", derandomize=False, **_UNTIMED)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# A shell that starts a job in the background (`cmd &` without job control, `nohup`) makes it ignore
# SIGINT, and the processes it starts inherit that: the Ctrl-C tests would then see no interrupt at
# all. The suite restores Python's own handler, so that those tests check the library, not how the
# run was launched (child processes then start with SIGINT's default action, as from a terminal).
import signal  # noqa: E402

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
