"""The definitions this station knows: shipped with it, registered by staff
(``kiosk station add-definition``) or approved by a doctor. Only a known definition's total
formula is ever run (station/formulas.py, in a process of its own).

Revision ID: 0007_known_definitions
Revises: 0006_history
"""

import sqlalchemy as sa
from alembic import op

revision = "0007_known_definitions"
down_revision = "0006_history"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("definitions") as batch:
        #: who made it known: "shipped", "registered by NAME" (the command line) or the approving doctor
        batch.add_column(sa.Column("known_by", sa.String(64)))
        batch.add_column(sa.Column("known_at", sa.String(40)))


def downgrade() -> None:
    with op.batch_alter_table("definitions") as batch:
        batch.drop_column("known_at")
        batch.drop_column("known_by")
