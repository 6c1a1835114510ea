"""In-process RoQME QoS engine."""
