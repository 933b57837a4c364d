"""``python -m htetro_opt.cli``: the same as the ``htetro-opt`` command."""

from htetro_opt.cli._entry import main

main()
