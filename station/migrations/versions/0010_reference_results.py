"""A clinician's own result beside the kiosk's, for a validation study (issue 36, part 8): one row
per answer a clinician entered for a session's item (the option, who entered it and when), kept
apart from what the kiosk sent, so it never reaches the inbox, an export or a total. Append-only
in the database itself, as the audit trail is: a change is a newer row, so who answered what, and
when, is never lost.

Revision ID: 0010_reference_results
Revises: 0008_order_relationship
"""

import sqlalchemy as sa
from alembic import op

revision = "0010_reference_results"
down_revision = "0009_tug_results"
branch_labels = None
depends_on = None

_SQLITE_TRIGGERS = [
    "CREATE TRIGGER reference_results_no_update BEFORE UPDATE ON reference_results "
    "BEGIN SELECT RAISE(ABORT, 'reference results are append-only'); END",
    "CREATE TRIGGER reference_results_no_delete BEFORE DELETE ON reference_results "
    "BEGIN SELECT RAISE(ABORT, 'reference results are append-only'); END",
]
_POSTGRES_TRIGGERS = [
    "CREATE FUNCTION reference_results_append_only() RETURNS trigger LANGUAGE plpgsql AS "
    "$$ BEGIN RAISE EXCEPTION 'reference results are append-only'; END $$",
    "CREATE TRIGGER reference_results_no_change BEFORE UPDATE OR DELETE ON reference_results "
    "FOR EACH ROW EXECUTE FUNCTION reference_results_append_only()",
]


def upgrade() -> None:
    op.create_table(
        "reference_results",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=True),
        sa.Column("session_id", sa.String(64), nullable=False),
        sa.Column("questionnaire_id", sa.String(64), nullable=False),
        sa.Column("item_id", sa.String(64), nullable=False),
        sa.Column("option", sa.Integer, nullable=False),
        sa.Column("entered_by", sa.String(64), nullable=False),
        sa.Column("entered_at", sa.String(40), nullable=False),
    )
    op.create_index("reference_results_session", "reference_results", ["session_id", "id"])
    op.create_index("reference_results_instrument", "reference_results", ["questionnaire_id", "session_id"])
    triggers = _POSTGRES_TRIGGERS if op.get_bind().dialect.name == "postgresql" else _SQLITE_TRIGGERS
    for statement in triggers:
        op.execute(statement)


def downgrade() -> None:
    if op.get_bind().dialect.name == "postgresql":
        op.execute("DROP TRIGGER reference_results_no_change ON reference_results")
        op.execute("DROP FUNCTION reference_results_append_only()")
    op.drop_index("reference_results_instrument", table_name="reference_results")
    op.drop_index("reference_results_session", table_name="reference_results")
    op.drop_table("reference_results")
