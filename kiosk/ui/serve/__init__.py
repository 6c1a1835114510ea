"""The kiosk served to a touch display's browser (textual-serve) behind its guard."""
