"""Every file the project loads or writes: bounded, positioned reading and owner-only writing.

Imports nothing of ours but :mod:`basis`."""
