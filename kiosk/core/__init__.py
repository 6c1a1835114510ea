"""The kiosk's pure domain: instruments, the session, adaptation, words, channels, clock, review.

No Textual, no SQLite, no threads."""
