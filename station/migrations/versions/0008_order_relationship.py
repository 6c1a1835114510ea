"""Who answers an ordered visit for the patient: the answerer's relationship (one of
kiosk.core.answerers.RELATIONSHIPS) and, for "other", its words; both empty when the station
did not say (orders from before, or the patient answers). Protocol §4.

Revision ID: 0008_order_relationship
Revises: 0007_known_definitions
"""

import sqlalchemy as sa
from alembic import op

revision = "0008_order_relationship"
down_revision = "0007_known_definitions"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("orders") as batch:
        batch.add_column(sa.Column("relationship", sa.String(16)))
        batch.add_column(sa.Column("relationship_text", sa.String(60)))


def downgrade() -> None:
    with op.batch_alter_table("orders") as batch:
        batch.drop_column("relationship_text")
        batch.drop_column("relationship")
