"""The ``minros`` command and its sub-commands; one module per tool."""
