"""The ward station (`kiosk station`): a web application where kiosks report and staff watch,
answer doctor calls and validate results.

One module per concept: :mod:`station.db` (tables, engine, migrations), :mod:`station.sync`
(the kiosk protocol's outbox intake), :mod:`station.ward` (live status, alerts, commands),
:mod:`station.validation` (corrections, sign-off, audit trail), :mod:`station.auth` (users,
kiosk tokens, login), :mod:`station.bus` (fan-out between station processes), :mod:`station.web`
(the Starlette routes, thin) and :mod:`station.cli` (start it, administer it). The station never
imports Textual or the kiosk's screens (an import-linter contract checks it).
"""
