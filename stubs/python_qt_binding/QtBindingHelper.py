"""python_qt_binding.QtBindingHelper: ROS's deprecated name, which only prints how to import
instead (as ROS's does)."""

print('Deprecation warning: the "python_qt_binding.QtBindingHelper" module is deprecated and will be removed in the near future.')
print("Replace your usage of QtBindingHelper with import statements like:")
print("  from python_qt_binding.QtCore import QObject")
print("  from python_qt_binding import QtGui, loadUi")
