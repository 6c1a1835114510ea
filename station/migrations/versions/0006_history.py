"""History never slows today's work: where a result's review stands is stored on its session
(``signed_at``: the time of the sign-off it stands under, NULL while it waits for validation),
written in the transaction of the sign-off or reopening, and every list the pages read has an
index (a patient's results and an identifier prefix, the month's sign-offs, the results waiting,
the inbox's order, open alerts, alerts by session, a session's rows and commands, orders by state).

Revision ID: 0006_history
Revises: 0005_orders
"""

import sqlalchemy as sa
from alembic import op

revision = "0006_history"
down_revision = "0005_orders"
branch_labels = None
depends_on = None

OPEN_ALERT = sa.text("ack_at IS NULL")


def upgrade() -> None:
    with op.batch_alter_table("sessions") as batch:
        batch.add_column(sa.Column("signed_at", sa.String(40)))
    # the latest sign-off or reopening of each session says where it stands (a reopened result
    # waits again): the same reading as kiosk.core.review.review_from_steps
    op.execute(
        """
        UPDATE sessions SET signed_at = (
            SELECT CASE WHEN a.action = 'sign_off' THEN a.at END FROM audit a
            WHERE a.session_id = sessions.id AND a.action IN ('sign_off', 'amend')
            ORDER BY a.id DESC LIMIT 1)
        """
    )
    op.create_index(
        "sessions_patient",
        "sessions",
        ["patient_id", "started_at"],
        postgresql_ops={"patient_id": "text_pattern_ops"},
    )
    op.create_index("sessions_waiting", "sessions", ["status", "signed_at"])
    op.create_index("sessions_signed_at", "sessions", ["signed_at"])
    op.create_index("sessions_finished", "sessions", ["status", "finished_at", "id"])
    op.create_index("sessions_kiosk_finished", "sessions", ["kiosk_id", "status", "finished_at"])
    op.create_index("sessions_started", "sessions", ["started_at"])
    op.create_index("inbox_session_seq", "inbox", ["session_id", "seq"])
    op.create_index("alerts_open", "alerts", ["id"], sqlite_where=OPEN_ALERT, postgresql_where=OPEN_ALERT)
    op.create_index("alerts_session", "alerts", ["session_id", "kind"])
    op.create_index("commands_session", "commands", ["session_id"])
    op.create_index("orders_state_ordered", "orders", ["state", "ordered_at"])
    op.create_index("orders_ordered", "orders", ["ordered_at"])
    op.create_index("visits_order", "visits", ["order_id"])


def downgrade() -> None:
    for name, table in (
        ("visits_order", "visits"),
        ("orders_ordered", "orders"),
        ("orders_state_ordered", "orders"),
        ("commands_session", "commands"),
        ("alerts_session", "alerts"),
        ("alerts_open", "alerts"),
        ("inbox_session_seq", "inbox"),
        ("sessions_started", "sessions"),
        ("sessions_kiosk_finished", "sessions"),
        ("sessions_finished", "sessions"),
        ("sessions_signed_at", "sessions"),
        ("sessions_waiting", "sessions"),
        ("sessions_patient", "sessions"),
    ):
        op.drop_index(name, table_name=table)
    with op.batch_alter_table("sessions") as batch:
        batch.drop_column("signed_at")
