"""The public names of :mod:`spine_mj.cli`, for type checkers and the docs; ``__init__.py``
loads each from its home on first use (``lazy_loader.attach_stub`` reads this file)."""

from .app import INPUT_ERROR_EXIT as INPUT_ERROR_EXIT
from .app import InputError as InputError
from .app import Progress as Progress
from .app import main as main
from .app import run as run
