"""Timed Up and Go results from the kiosks (issue 34): one row per ``record_tug`` row a kiosk sent
(protocol: docs/station-protocol.md, "Timed Up and Go"), with the time staff took, how, the
camera's phases and quality flags, the staff decision and who made it, and the visit it belongs
to. Never landmarks, never pictures.

Revision ID: 0009_tug_results
Revises: 0008_order_relationship
"""

import sqlalchemy as sa
from alembic import op

revision = "0009_tug_results"
down_revision = "0008_order_relationship"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "tug_results",
        sa.Column("id", sa.String(64), primary_key=True),
        sa.Column("kiosk_id", sa.String(64), nullable=False),
        sa.Column("seq", sa.BigInteger, nullable=False),
        sa.Column("patient_id", sa.String(64), nullable=False),
        sa.Column("at", sa.String(40), nullable=False),
        sa.Column("visit_kind", sa.String(16)),
        sa.Column("order_id", sa.String(32)),
        sa.Column("visit_id", sa.String(64)),
        sa.Column("confirmed_by", sa.String(64), nullable=False),
        sa.Column("decision", sa.String(16), nullable=False),
        sa.Column("decided_by", sa.String(64), nullable=False),
        sa.Column("total_s", sa.Float),
        sa.Column("method", sa.String(16)),
        sa.Column("camera_total_s", sa.Float),
        sa.Column("threshold_s", sa.Float, nullable=False),
        sa.Column("phases", sa.Text, nullable=False),
        sa.Column("reasons", sa.Text, nullable=False),
        sa.Column("person_share", sa.Float, nullable=False),
        sa.Column("body_cut_off", sa.Boolean, nullable=False),
        sa.Column("turn_seen", sa.Boolean, nullable=False),
        sa.Column("get_up_go", sa.Integer),
        sa.Column("walking_aid", sa.String(16)),
        sa.Column("simulated", sa.Boolean, nullable=False, server_default=sa.false()),
        sa.Column("export", sa.Text),
        sa.Column("received_at", sa.Float, nullable=False),
        sa.UniqueConstraint("kiosk_id", "seq", name="tug_results_row"),
        sa.CheckConstraint("decision IN ('accepted', 'stopwatch', 'rejected')", name="tug_results_decision"),
    )
    op.create_index("tug_results_patient", "tug_results", ["patient_id", "at"])
    op.create_index("tug_results_order", "tug_results", ["order_id"])
    op.create_index("tug_results_visit", "tug_results", ["visit_id"])


def downgrade() -> None:
    op.drop_table("tug_results")
