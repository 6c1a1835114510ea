"""Visits ordered from the ward: orders, how each session began (visits), and the wrong codes a
kiosk sent (to stop guessing).

Revision ID: 0005_orders
Revises: 0001
"""

import sqlalchemy as sa
from alembic import op

revision = "0005_orders"
down_revision = "0003_captured_definitions"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "orders",
        sa.Column("id", sa.String(32), primary_key=True),
        sa.Column("kiosk_id", sa.String(64), nullable=False),
        sa.Column("patient_id", sa.String(64), nullable=False),
        sa.Column("instruments", sa.Text, nullable=False),
        sa.Column("language", sa.String(8), nullable=False),
        sa.Column("answered_by", sa.String(16), nullable=False),
        sa.Column("code", sa.String(8), nullable=False),
        sa.Column("state", sa.String(24), nullable=False),
        sa.Column("ordered_by", sa.String(64), nullable=False),
        sa.Column("ordered_at", sa.String(40), nullable=False),
        sa.Column("session_id", sa.String(64)),
        sa.Column("updated_at", sa.String(40), nullable=False),
        sa.CheckConstraint(
            "state IN ('ordered', 'in_progress', 'awaiting_validation', 'signed_off', 'cancelled')", name="orders_state"
        ),
    )
    op.create_index("orders_kiosk_state", "orders", ["kiosk_id", "state"])
    op.create_index("orders_patient", "orders", ["patient_id"])
    op.create_index("orders_session", "orders", ["session_id"])
    op.create_table(
        "visits",
        sa.Column("session_id", sa.String(64), primary_key=True),
        sa.Column("kind", sa.String(16), nullable=False),
        sa.Column("order_id", sa.String(32)),
    )
    op.create_table(
        "order_code_failures",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("kiosk_id", sa.String(64), nullable=False),
        sa.Column("at", sa.Float, nullable=False),
    )
    op.create_index("order_code_failures_kiosk", "order_code_failures", ["kiosk_id", "at"])


def downgrade() -> None:
    for table in ("order_code_failures", "visits", "orders"):
        op.drop_table(table)
