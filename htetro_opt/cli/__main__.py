"""``python -m htetro_opt.cli``: the same as the ``htetro-opt`` command."""

from htetro_opt.cli import main_entry

main_entry()
