"""Reusable display pieces of the kiosk: answer buttons, progress, channel and adaptation bars."""
