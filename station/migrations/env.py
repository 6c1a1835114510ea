"""Alembic environment: the station runs its migrations itself (``station.db.migrate``) on the
connection it passes in ``config.attributes``."""

from alembic import context

connection = context.config.attributes["connection"]
context.configure(connection=connection, render_as_batch=connection.dialect.name == "sqlite")
with context.begin_transaction():
    context.run_migrations()
