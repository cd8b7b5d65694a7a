"""dynamic_reconfigure stand-in: reconfigurable parameters served by minros.dynamic_reconfigure."""

from minros.dynamic_reconfigure import (  # noqa: F401
    DynamicReconfigureCallbackException,
    DynamicReconfigureException,
    DynamicReconfigureParameterException,
    find_reconfigure_services,
    get_parameter_names,
)
