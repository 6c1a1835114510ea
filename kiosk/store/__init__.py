"""The kiosk's SQLite store: sessions kept crash-safe, leases, migrations and the records it gives back."""
