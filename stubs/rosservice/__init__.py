"""Stand-in for rosservice's Python API (minros.cli.service: the code the command runs)."""

from minros.cli.service import (  # noqa: F401
    NAME,
    ROSServiceException,
    ROSServiceIOException,
    has_service_args,
    rosservice_find,
    rosservicemain,
)
from minros.cli.service import rosservice_call_service as call_service  # noqa: F401
from minros.cli.service import rosservice_get_service_args as get_service_args  # noqa: F401
from minros.cli.service import (  # noqa: F401
    rosservice_get_service_class_by_name as get_service_class_by_name,
)
from minros.cli.service import rosservice_get_service_headers as get_service_headers  # noqa: F401
from minros.cli.service import rosservice_get_service_list as get_service_list  # noqa: F401
from minros.cli.service import rosservice_get_service_node as get_service_node  # noqa: F401
from minros.cli.service import rosservice_get_service_type as get_service_type  # noqa: F401
from minros.cli.service import rosservice_get_service_uri as get_service_uri  # noqa: F401
