"""The kiosk's screens, one per file. They render what the app hands them and forward input."""
