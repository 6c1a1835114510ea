"""The `kiosk` sub-commands, one module each, imported only when asked for."""
