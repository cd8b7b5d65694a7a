"""genmsg.gentools: md5 sums and full texts of specs (minros.msgs.loader)."""

from minros.msgs.loader import (  # noqa: F401
    compute_full_text,
    compute_full_type_name,
    compute_md5,
    compute_md5_text,
)
