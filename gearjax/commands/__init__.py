"""Sub-commands of the ``gearjax`` CLI, one module each (see ``gearjax/cli.py``)."""
