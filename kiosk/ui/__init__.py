"""The kiosk's Textual UI: a thin app, its controller, screens, widgets and the served page."""
