"""Server-side staff login sessions (revocable: logout, password change, user removal end them)
and an index for throttling logins per (name, address).

Revision ID: 0002_staff_sessions
Revises: 0001
"""

import sqlalchemy as sa
from alembic import op

revision = "0002_staff_sessions"
down_revision = "0001"
branch_labels = None
depends_on = None


def upgrade() -> None:
    op.create_table(
        "staff_sessions",
        # SHA-256 of the random session id in the login cookie: a copy of the database opens nothing
        sa.Column("id_hash", sa.String(64), primary_key=True),
        sa.Column("user_name", sa.String(64), sa.ForeignKey("users.name", ondelete="CASCADE"), nullable=False),
        sa.Column("created_at", sa.Float, nullable=False),
        sa.Column("expires_at", sa.Float, nullable=False),
    )
    op.create_index("staff_sessions_user", "staff_sessions", ["user_name"])
    op.create_index("login_failures_name_address", "login_failures", ["name", "address"])


def downgrade() -> None:
    op.drop_index("login_failures_name_address", "login_failures")
    op.drop_table("staff_sessions")
