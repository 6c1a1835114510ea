"""Captured definitions: the questionnaire each session ran, stored once per content, and which
definition describes each session (``attached_later`` when this upgrade gave it the bundled one,
because the kiosk sent none).

Revision ID: 0003_captured_definitions
Revises: 0001
"""

from datetime import UTC, datetime

import sqlalchemy as sa
from alembic import op

revision = "0003_captured_definitions"
down_revision = "0002_staff_sessions"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "definitions",
        sa.Column("sha256", sa.String(64), primary_key=True),
        sa.Column("questionnaire_id", sa.Text, nullable=False),
        sa.Column("version", sa.Text, nullable=False),
        sa.Column("body", sa.Text, nullable=False),
        sa.Column("stored_at", sa.String(40), nullable=False),
    )
    with op.batch_alter_table("sessions") as batch:
        batch.add_column(sa.Column("definition_sha256", sa.String(64), nullable=True))
        batch.add_column(sa.Column("definition_attached_later", sa.Boolean, nullable=False, server_default=sa.false()))
    bind = op.get_bind()
    if bind.execute(sa.text("SELECT COUNT(*) FROM sessions")).scalar():
        # the definition in force now: the bundled questionnaire (what the station described every
        # session with until now), marked attached later
        from kiosk.core.questionnaire import load_questionnaire
        from kiosk.core.questionnaire.definition import canonical, canonical_json, digest

        definition = canonical(load_questionnaire())
        sha = digest(definition)
        bind.execute(
            sa.text(
                "INSERT INTO definitions (sha256, questionnaire_id, version, body, stored_at)"
                " VALUES (:sha, :id, :version, :body, :at)"
            ),
            {
                "sha": sha,
                "id": definition["id"],
                "version": definition["version"],
                "body": canonical_json(definition),
                "at": datetime.now(UTC).isoformat(timespec="milliseconds"),
            },
        )
        bind.execute(
            sa.text("UPDATE sessions SET definition_sha256 = :sha, definition_attached_later = :later"),
            {"sha": sha, "later": True},
        )


def downgrade() -> None:
    with op.batch_alter_table("sessions") as batch:
        batch.drop_column("definition_attached_later")
        batch.drop_column("definition_sha256")
    op.drop_table("definitions")
