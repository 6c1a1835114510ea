"""Barthel kiosk: patient-facing app, session core and channels."""
