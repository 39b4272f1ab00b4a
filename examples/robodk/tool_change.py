# Tool changes: the station's tools by item, by number and a new tool made by the script
# (AddTool gives it the next free tool number, as a Fanuc UTOOL needs one).
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
frame = RDK.Item('Table', ITEM_TYPE_FRAME)
target = RDK.Item('Target 1')
home = RDK.Item('Home')

tools = [t for t in robot.Childs() if t.Type() == ITEM_TYPE_TOOL]
print('Tools: %s' % [t.Name() for t in tools])

RDK.ProgramStart('ToolChange')
robot.setPoseFrame(frame)
robot.setSpeed(200)
robot.MoveJ(home)

# 1. by item, 2. by number, 3. a new tool: a probe 180 mm out of the flange, tilted like the others
probe = robot.AddTool(roty(115 * pi / 180) * transl(0, 0, 180), 'Probe')
for tool in [RDK.Item('Torch', ITEM_TYPE_TOOL), 2, probe]:
    robot.RunInstruction('ChangeTool', INSTRUCTION_CALL_PROGRAM)
    robot.setPoseTool(tool)
    name = tool.Name() if isinstance(tool, Item) else 'tool %i' % tool
    robot.RunInstruction('Using ' + name, INSTRUCTION_COMMENT)
    robot.MoveJ(target.Pose() * transl(0, 0, -50))
    robot.MoveL(target)
    robot.MoveL(target.Pose() * transl(0, 0, -50))
robot.MoveJ(home)
