"""Settings for the whole test run (the notebooks included)."""

import os

# The notebooks read HTETRO_OPT_SMALL: with it they run at small settings (seconds, not minutes);
# their kernels inherit this process's environment.
os.environ.setdefault("HTETRO_OPT_SMALL", "1")
